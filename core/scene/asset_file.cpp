// Reading an untrusted asset's files: only regular files, never more than a stated limit, and an
// asset's external references only inside the asset's own folder (symlinks resolved).
#include "core/scene/asset_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

namespace arpipe {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int error) { return std::error_code(error, std::generic_category()).message(); }

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

}  // namespace

std::optional<std::vector<unsigned char>> read_regular_file(const fs::path& path, uint64_t limit, std::string* why) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it.
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (fd.get() < 0) {
    *why = fmt::format("cannot open: {}", errno_text(errno));
    return std::nullopt;
  }
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0) {
    *why = fmt::format("cannot stat: {}", errno_text(errno));
    return std::nullopt;
  }
  if (!S_ISREG(info.st_mode)) {
    *why = fmt::format("not a regular file ({})", file_kind(info.st_mode));
    return std::nullopt;
  }
  const uint64_t size = uint64_t(std::max<off_t>(info.st_size, 0));
  if (size > limit) {
    *why = fmt::format("{} bytes, over the limit of {} bytes", size, limit);
    return std::nullopt;
  }
  std::vector<unsigned char> bytes(size);
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      *why = fmt::format("read error: {}", errno_text(errno));
      return std::nullopt;
    }
    if (n == 0) {
      *why = fmt::format("shrank to {} bytes while being read ({} expected)", done, bytes.size());
      return std::nullopt;
    }
    done += size_t(n);
  }
  return bytes;
}

std::optional<fs::path> canonical_folder(const fs::path& file, std::string* why) {
  const fs::path parent = file.parent_path();
  std::error_code error;
  fs::path folder = fs::canonical(parent.empty() ? fs::path(".") : parent, error);
  if (error) {
    *why = fmt::format("cannot resolve its folder: {}", error.message());
    return std::nullopt;
  }
  return folder;
}

std::optional<fs::path> resolve_inside_folder(const fs::path& folder, const std::string& reference, std::string* why) {
  if (reference.empty() || reference.find('\0') != std::string::npos) {
    *why = "an empty name or one with a NUL byte";
    return std::nullopt;
  }
  // As glTF URIs are joined: folder + "/" + reference, also for a reference starting with '/'.
  std::error_code error;
  const fs::path resolved = fs::canonical(fs::path(folder.string() + "/" + reference), error);
  if (error) {
    *why = fmt::format("cannot open: {}", error.message());
    return std::nullopt;
  }
  // Component by component: "/a/bc" is not inside "/a/b".
  auto [in_folder, in_resolved] = std::mismatch(folder.begin(), folder.end(), resolved.begin(), resolved.end());
  if (in_folder != folder.end() || in_resolved == resolved.end()) {
    *why = fmt::format("resolves to a file outside the asset's folder {} (references must stay inside it)",
                       folder.string());
    return std::nullopt;
  }
  return resolved;
}

}  // namespace arpipe
