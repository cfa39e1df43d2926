#include "capture/sinks/output_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "capture/sinks/output_path.h"

namespace arpipe {

namespace {

// Writes all of data (retrying short writes and EINTR); at is advanced (pwrite) or unused (stream).
int write_all(int fd, bool positioned, const uint8_t* data, size_t size, uint64_t& at) noexcept {
  while (size > 0) {
    const ssize_t n = positioned ? ::pwrite(fd, data, size, off_t(at)) : ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= size_t(n);
    at += uint64_t(n);
  }
  return 0;
}

// Keeps SIGPIPE away from a write to a pipe whose reader left (EPIPE is the answer instead): the
// signal is blocked in this thread for the write and a SIGPIPE the write raised is taken back, so
// the daemon keeps running whether or not it ignores SIGPIPE.
class SigpipeGuard {
 public:
  SigpipeGuard() {
    sigemptyset(&pipe_set_);
    sigaddset(&pipe_set_, SIGPIPE);
    sigset_t pending;
    sigpending(&pending);
    was_pending_ = sigismember(&pending, SIGPIPE) == 1;
    pthread_sigmask(SIG_BLOCK, &pipe_set_, &previous_);
  }
  ~SigpipeGuard() {
    if (raised_ && !was_pending_) {
      const timespec zero{};
      while (sigtimedwait(&pipe_set_, nullptr, &zero) < 0 && errno == EINTR) {
      }
    }
    pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
  }
  void saw(int error) { raised_ = raised_ || error == EPIPE; }

 private:
  sigset_t pipe_set_{}, previous_{};
  bool was_pending_ = false, raised_ = false;
};

}  // namespace

OutputFile::OutputFile(const std::filesystem::path& path, std::string_view config_key) : path_(path) {
  const auto fail = [&](std::string_view why) {
    return std::runtime_error(fmt::format("{} (config {}): {}", path.string(), config_key, why));
  };
  create_parent_directory(path, config_key);
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(path, ec))) {
    path_ = std::filesystem::canonical(path, ec);  // replace the file it points to, not the link
    if (ec) throw fail(fmt::format("cannot follow the symbolic link: {}", ec.message()));
  }
  struct stat st {};
  const bool exists = ::stat(path_.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw fail("cannot open for writing: Is a directory");
  regular_ = !exists || S_ISREG(st.st_mode);
  if (regular_) {
    const std::string name = path_.filename().string();
    remove_stale_temporaries(path_.parent_path(), [&](std::string_view target) { return target == name; });
    temporary_ = temporary_name(path_);
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0)
      throw fail(fmt::format("cannot open {} for writing: {}", temporary_.filename().string(), std::strerror(errno)));
  } else {
    // A FIFO blocks here until a reader opens it, as a player reading the video would.
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd_ < 0) throw fail(fmt::format("cannot open for writing: {}", std::strerror(errno)));
    pipe_like_ = S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode);
    fifo_ = S_ISFIFO(st.st_mode);
    committed_ = true;
  }
}

OutputFile::~OutputFile() {
  if (fd_ < 0) return;
  if (!committed_) {
    ::close(fd_);
    ::unlink(temporary_.c_str());
    return;
  }
  sync();
  ::close(fd_);
}

bool OutputFile::commit(std::string& error) noexcept {
  if (committed_) return true;
  committed_ = true;
  // Synced first: after a power loss the name holds this run's start or the previous output, never a hole.
  if (::fdatasync(fd_) != 0 || ::rename(temporary_.c_str(), path_.c_str()) != 0) {
    error = std::strerror(errno);
    return false;
  }
  sync_directory(path_.parent_path());
  return true;
}

int OutputFile::append(std::initializer_list<std::span<const uint8_t>> parts) noexcept {
  if (fd_ < 0) {
    // A FIFO whose reader left: the next reader (a player started again) is found by opening it
    // anew, without blocking; none yet is the same broken pipe as before.
    if (!fifo_) return EBADF;
    fd_ = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) return errno == ENXIO ? EPIPE : errno;
    const int flags = ::fcntl(fd_, F_GETFL);
    if (flags < 0 || ::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK) != 0) {
      const int error = errno;
      ::close(fd_);
      fd_ = -1;
      return error;
    }
  }
  if (cut_back_pending_) {
    if (::ftruncate(fd_, off_t(end_)) != 0) return errno;
    cut_back_pending_ = false;
  }
  uint64_t at = end_;
  int error = 0;
  {
    std::optional<SigpipeGuard> guard;
    if (pipe_like_) guard.emplace();
    for (const auto& part : parts) {
      error = write_all(fd_, regular_, part.data(), part.size(), at);
      if (error) break;
    }
    if (guard) guard->saw(error);
  }
  if (error) {
    if (regular_ && at != end_ && ::ftruncate(fd_, off_t(end_)) != 0) cut_back_pending_ = true;
    // The pipe keeps what the reader that left did not read while any end is open: closed, its
    // buffer goes, so the next reader starts with the next record, not the rest of this one.
    if (fifo_ && error == EPIPE) {
      ::close(fd_);
      fd_ = -1;
    }
    return error;
  }
  if (regular_) end_ = at;
  return 0;
}

bool OutputFile::sync() noexcept { return !regular_ || ::fsync(fd_) == 0; }

}  // namespace arpipe
