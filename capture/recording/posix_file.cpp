// POSIX file I/O for the recording writer and reader: positioned, retried on EINTR and short
// transfers, every error reported with the path it concerns.
#include "capture/recording/posix_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>
#include <utility>

#include "core/config/regular_file.h"

namespace arpipe {

namespace {
[[noreturn]] void fail(const std::string& what, const std::filesystem::path& path) {
  throw std::system_error(errno, std::generic_category(), what + " " + path.string());
}
}  // namespace

PosixFile::PosixFile(const std::filesystem::path& path, Mode mode) : path_(path) {
  if (mode == Mode::Read) {
    // A recording's parts are regular files: a FIFO would block open() and a device never ends.
    fd_ = open_regular_file(path, "recording file");
    return;
  }
  do {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  } while (fd_ < 0 && errno == EINTR);
  if (fd_ < 0) fail("cannot create", path);
}

PosixFile::~PosixFile() { close(); }

PosixFile::PosixFile(PosixFile&& other) noexcept : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)) {}

PosixFile& PosixFile::operator=(PosixFile&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
  }
  return *this;
}

void PosixFile::write_at(uint64_t offset, const void* data, size_t size) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::pwrite(fd_, bytes, size, off_t(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot write", path_);
    }
    bytes += n;
    offset += uint64_t(n);
    size -= size_t(n);
  }
}

bool PosixFile::read_at(uint64_t offset, void* data, size_t size) const {
  auto* bytes = static_cast<uint8_t*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd_, bytes, size, off_t(offset));
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("cannot read", path_);
    }
    if (n == 0) return false;
    bytes += n;
    offset += uint64_t(n);
    size -= size_t(n);
  }
  return true;
}

size_t PosixFile::read_some(uint64_t offset, void* data, size_t size) const {
  for (;;) {
    const ssize_t n = ::pread(fd_, data, size, off_t(offset));
    if (n >= 0) return size_t(n);
    if (errno != EINTR) fail("cannot read", path_);
  }
}

uint64_t PosixFile::size() const {
  struct stat st {};
  if (::fstat(fd_, &st) != 0) fail("cannot stat", path_);
  return uint64_t(st.st_size);
}

void PosixFile::truncate(uint64_t size) {
  if (::ftruncate(fd_, off_t(size)) != 0) fail("cannot truncate", path_);
}

void PosixFile::sync() {
  if (::fsync(fd_) != 0) fail("cannot fsync", path_);
}

void PosixFile::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void PosixFile::sync_directory(const std::filesystem::path& dir) {
  PosixFile d;
  d.path_ = dir;
  do {
    d.fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  } while (d.fd_ < 0 && errno == EINTR);
  if (d.fd_ < 0) fail("cannot open directory", dir);
  // Some file systems refuse fsync on directories (EINVAL); their names are durable anyway.
  if (::fsync(d.fd_) != 0 && errno != EINVAL) fail("cannot fsync directory", dir);
}

}  // namespace arpipe
