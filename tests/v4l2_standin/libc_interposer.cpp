// The libc functions the stand-in interposes (open*, close, ioctl, mmap*, poll, read): calls on
// served paths and tracked fds go to the registry, everything else to the next definition (libc).
#undef _FORTIFY_SOURCE  // this file defines open() and friends; fortify would wrap them inline

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "standin_config.h"
#include "standin_registry.h"

using arpipe::standin::is_serving;
using arpipe::standin::is_tracked;
using arpipe::standin::Registry;

namespace {

// The next definition of a libc function, looked up once (dlsym before any constructor is fine).
template <typename F>
F next_symbol(std::atomic<F>& slot, const char* name) {
  F f = slot.load(std::memory_order_acquire);
  if (f == nullptr) {
    f = reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
    if (f == nullptr) {
      std::fprintf(stderr, "arpipe-v4l2-standin: cannot find the next %s: %s\n", name, ::dlerror());
      std::abort();
    }
    slot.store(f, std::memory_order_release);
  }
  return f;
}
#define ARPIPE_REAL(type, name)                       \
  [] {                                                \
    static std::atomic<type> slot{nullptr};           \
    return next_symbol<type>(slot, #name);            \
  }()

using OpenFn = int (*)(const char*, int, ...);
using OpenatFn = int (*)(int, const char*, int, ...);
using Open2Fn = int (*)(const char*, int);
using Openat2Fn = int (*)(int, const char*, int);
using CloseFn = int (*)(int);
using IoctlFn = int (*)(int, unsigned long, ...);
using MmapFn = void* (*)(void*, size_t, int, int, int, off_t);
using PollFn = int (*)(pollfd*, nfds_t, int);
using PollChkFn = int (*)(pollfd*, nfds_t, int, size_t);
using ReadFn = ssize_t (*)(int, void*, size_t);
using ReadChkFn = ssize_t (*)(int, void*, size_t, size_t);

bool wants_mode(int flags) { return (flags & O_CREAT) != 0 || (flags & O_TMPFILE) == O_TMPFILE; }

// The served path that (dirfd, path) names, or "" (cheap while nothing is served).
std::string served(int dirfd, const char* path) {
  if (!is_serving() || path == nullptr) return "";
  std::string full = path;
  if (full.empty()) return "";
  if (full[0] != '/' && dirfd != AT_FDCWD) {
    char link[64], dir[4096];
    std::snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
    const ssize_t n = ::readlink(link, dir, sizeof dir - 1);
    if (n <= 0) return "";
    dir[n] = '\0';
    full = std::string(dir) + "/" + full;
  }
  return Registry::get().served_path(arpipe::standin::normal_device_path(full));
}

}  // namespace

#define ARPIPE_EXPORT extern "C" __attribute__((visibility("default")))

ARPIPE_EXPORT int open(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenFn, open)(path, flags, mode);
}

ARPIPE_EXPORT int open64(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenFn, open64)(path, flags, mode);
}

ARPIPE_EXPORT int openat(int dirfd, const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenatFn, openat)(dirfd, path, flags, mode);
}

ARPIPE_EXPORT int openat64(int dirfd, const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenatFn, openat64)(dirfd, path, flags, mode);
}

// The _FORTIFY_SOURCE entry points a host built with fortification calls instead.
ARPIPE_EXPORT int __open_2(const char* path, int flags) {
  if (const std::string s = served(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Open2Fn, __open_2)(path, flags);
}
ARPIPE_EXPORT int __open64_2(const char* path, int flags) {
  if (const std::string s = served(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Open2Fn, __open64_2)(path, flags);
}
ARPIPE_EXPORT int __openat_2(int dirfd, const char* path, int flags) {
  if (const std::string s = served(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Openat2Fn, __openat_2)(dirfd, path, flags);
}
ARPIPE_EXPORT int __openat64_2(int dirfd, const char* path, int flags) {
  if (const std::string s = served(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Openat2Fn, __openat64_2)(dirfd, path, flags);
}

ARPIPE_EXPORT int close(int fd) {
  if (is_tracked(fd)) Registry::get().close(fd);
  return ARPIPE_REAL(CloseFn, close)(fd);
}

ARPIPE_EXPORT int ioctl(int fd, unsigned long request, ...) noexcept {
  va_list ap;
  va_start(ap, request);
  void* arg = va_arg(ap, void*);
  va_end(ap);
  if (is_tracked(fd)) {
    bool handled = false;
    const int r = Registry::get().ioctl(fd, request, arg, handled);
    if (handled) return r;
  }
  return ARPIPE_REAL(IoctlFn, ioctl)(fd, request, arg);
}

ARPIPE_EXPORT void* mmap(void* addr, size_t length, int prot, int flags, int fd, off_t offset) noexcept {
  if (is_tracked(fd)) {
    bool handled = false;
    void* p = Registry::get().mmap(fd, addr, length, prot, flags, offset, handled);
    if (handled) return p;
  }
  return ARPIPE_REAL(MmapFn, mmap)(addr, length, prot, flags, fd, offset);
}

ARPIPE_EXPORT void* mmap64(void* addr, size_t length, int prot, int flags, int fd, off64_t offset) noexcept {
  if (is_tracked(fd)) {
    bool handled = false;
    void* p = Registry::get().mmap(fd, addr, length, prot, flags, offset, handled);
    if (handled) return p;
  }
  return ARPIPE_REAL(MmapFn, mmap64)(addr, length, prot, flags, fd, offset);
}

namespace {
bool any_tracked(const pollfd* fds, nfds_t nfds) {
  for (nfds_t i = 0; i < nfds; ++i)
    if (is_tracked(fds[i].fd)) return true;
  return false;
}
int real_poll(pollfd* fds, nfds_t nfds, int timeout) { return ARPIPE_REAL(PollFn, poll)(fds, nfds, timeout); }
}  // namespace

// glibc declares poll's fds write-only (__attr_access ((__write_only__, 1, 2))), so GCC at -O1
// (CI's sanitizer build) warns that reading the caller's events "may be used uninitialized"; the
// caller fills them in, as poll(2) requires.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
ARPIPE_EXPORT int poll(pollfd* fds, nfds_t nfds, int timeout) {
  if (fds != nullptr && any_tracked(fds, nfds)) return Registry::get().poll(fds, nfds, timeout, real_poll);
  return real_poll(fds, nfds, timeout);
}
#pragma GCC diagnostic pop

ARPIPE_EXPORT int __poll_chk(pollfd* fds, nfds_t nfds, int timeout, size_t fdslen) {
  if (fds != nullptr && nfds <= fdslen / sizeof(pollfd) && any_tracked(fds, nfds))
    return Registry::get().poll(fds, nfds, timeout, real_poll);
  return ARPIPE_REAL(PollChkFn, __poll_chk)(fds, nfds, timeout, fdslen);
}

ARPIPE_EXPORT ssize_t read(int fd, void* buf, size_t count) {
  if (is_tracked(fd)) {  // no V4L2_CAP_READWRITE
    errno = EINVAL;
    return -1;
  }
  return ARPIPE_REAL(ReadFn, read)(fd, buf, count);
}

ARPIPE_EXPORT ssize_t __read_chk(int fd, void* buf, size_t count, size_t buflen) {
  if (is_tracked(fd)) {
    errno = EINVAL;
    return -1;
  }
  return ARPIPE_REAL(ReadChkFn, __read_chk)(fd, buf, count, buflen);
}
