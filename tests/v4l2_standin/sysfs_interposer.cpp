// fopen of /sys/dev/char/81:N/uevent for a served node's minor: the few lines v4l-utils read to
// learn what a character device is (mi_media_detect_type wants DEVNAME=video...). The rest of
// /sys/class/video4linux is not faked.
#undef _FORTIFY_SOURCE

#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "next_symbol.h"
#include "standin_registry.h"

namespace {

using FopenFn = FILE* (*)(const char*, const char*);

// The uevent text of a served node's /sys/dev/char/81:minor/uevent, or "" when `path` is not one.
std::string uevent_of(const char* path) {
  if (!arpipe::standin::is_serving() || path == nullptr) return "";
  unsigned major = 0, minor = 0;
  char tail[16] = "";
  if (std::sscanf(path, "/sys/dev/char/%u:%u/%15s", &major, &minor, tail) != 3 || std::strcmp(tail, "uevent") != 0 ||
      major != arpipe::standin::kVideoMajor)
    return "";
  const std::string served = arpipe::standin::served_path_of_minor(minor);
  if (served.empty()) return "";
  std::string name = served.substr(served.rfind('/') + 1);
  if (name.rfind("video", 0) != 0) name = fmt::format("video{}", minor);  // what v4l-utils look for
  return fmt::format("MAJOR={}\nMINOR={}\nDEVNAME={}\n", major, minor, name);
}

// A read-only FILE over `text` (a memfd, so fclose frees it like any file).
FILE* text_file(const std::string& text) {
  const int fd = ::memfd_create("arpipe-v4l2-standin-sysfs", MFD_CLOEXEC);
  if (fd < 0) return nullptr;
  if (::pwrite(fd, text.data(), text.size(), 0) != ssize_t(text.size())) {
    ::close(fd);
    return nullptr;
  }
  FILE* f = ::fdopen(fd, "r");
  if (f == nullptr) ::close(fd);
  return f;
}

}  // namespace

#define ARPIPE_EXPORT extern "C" __attribute__((visibility("default")))

ARPIPE_EXPORT FILE* fopen(const char* path, const char* mode) {
  if (const std::string text = uevent_of(path); !text.empty()) return text_file(text);
  return ARPIPE_REAL(FopenFn, fopen)(path, mode);
}

ARPIPE_EXPORT FILE* fopen64(const char* path, const char* mode) {
  if (const std::string text = uevent_of(path); !text.empty()) return text_file(text);
  return ARPIPE_REAL(FopenFn, fopen64)(path, mode);
}
