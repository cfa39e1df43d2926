// Regular-file-only opening: O_NONBLOCK for the open, fstat/fstatfs checks, then blocking reads.
#include "core/config/regular_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace arpipe {

namespace {

const char* file_type_phrase(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "not a regular file";
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int release() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

 private:
  int fd_;
};

}  // namespace

FileAccessError::FileAccessError(const std::filesystem::path& path, std::string_view what, std::string reason,
                                 std::string_view action)
    : std::runtime_error(fmt::format("{}: cannot {} {}: {}", path.string(), action, what, reason)),
      path_(path),
      reason_(std::move(reason)),
      action_(action) {}

int open_regular_file(const std::filesystem::path& path, std::string_view what) {
  if (path.empty()) throw FileAccessError(path, what, "the path is empty");
  int raw = -1;
  do {
    raw = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  } while (raw < 0 && errno == EINTR);
  if (raw < 0) throw FileAccessError(path, what, std::strerror(errno), "open");
  Fd fd(raw);
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    throw FileAccessError(path, what, std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw FileAccessError(path, what, fmt::format("it is {}, expected a regular file", file_type_phrase(st.st_mode)));
  struct statfs fs {};
  if (::fstatfs(fd.get(), &fs) == 0 && (fs.f_type == PROC_SUPER_MAGIC || fs.f_type == SYSFS_MAGIC))
    throw FileAccessError(path, what, fmt::format("it is on {}, expected a regular file on disk",
                                                  fs.f_type == PROC_SUPER_MAGIC ? "/proc" : "/sys"));
  const int flags = ::fcntl(fd.get(), F_GETFL);
  if (flags < 0 || ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK) != 0)
    throw FileAccessError(path, what, std::strerror(errno));
  return fd.release();
}

std::string read_regular_file(const std::filesystem::path& path, std::string_view what, uint64_t max_bytes) {
  Fd fd(open_regular_file(path, what));
  // Refused by its size before a byte is read; the loop below still stops a file that grows.
  struct stat st {};
  if (::fstat(fd.get(), &st) == 0 && uint64_t(st.st_size) > max_bytes)
    throw FileAccessError(path, what, fmt::format("it is larger than the limit of {} bytes", max_bytes));
  std::string bytes;
  bytes.reserve(size_t(st.st_size));
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd.get(), buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw FileAccessError(path, what, std::strerror(errno));
    }
    if (n == 0) break;
    if (bytes.size() + uint64_t(n) > max_bytes)
      throw FileAccessError(path, what, fmt::format("it is larger than the limit of {} bytes", max_bytes));
    bytes.append(buffer, size_t(n));
  }
  return bytes;
}

}  // namespace arpipe
