// Opening a file that untrusted input names (config, scene, board, recording part, camera model,
// HDR image): regular files only, so a FIFO cannot block, a device cannot feed endless bytes, and
// /proc or /sys cannot leak into error messages; reads stop at a declared size limit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace arpipe {

// A file that cannot be used: what() reads "<path>: cannot open <what>: <reason>" when open() failed
// (no such file, a symlink loop, no permission) and "<path>: cannot read <what>: <reason>" for the
// rest; reason() alone ("No such file or directory", "it is a FIFO (named pipe), expected a regular
// file", ...) is for loaders that word the message in their own terms.
class FileAccessError : public std::runtime_error {
 public:
  FileAccessError(const std::filesystem::path& path, std::string_view what, std::string reason,
                  std::string_view action = "read");
  const std::filesystem::path& path() const { return path_; }
  const std::string& reason() const { return reason_; }
  // "cannot open: <reason>" or "cannot read: <reason>", for messages that name the file elsewhere.
  std::string action_and_reason() const { return "cannot " + action_ + ": " + reason_; }

 private:
  std::filesystem::path path_;
  std::string reason_;
  std::string action_;
};

// Opens `path` read-only and returns the descriptor (O_CLOEXEC; the caller closes it). Opening uses
// O_NONBLOCK, so a FIFO without a writer cannot block; then fstat refuses anything but a regular
// file (directory, FIFO, socket, device) and fstatfs anything on procfs or sysfs; O_NONBLOCK is
// cleared again. `what` names the file's role in messages ("config file", "camera model").
// Throws FileAccessError; a symlink loop reads "cannot open <what>: Too many levels of symbolic links".
int open_regular_file(const std::filesystem::path& path, std::string_view what);

// The whole file's bytes, opened as above; a file larger than max_bytes is refused with the limit
// in the message (checked while reading, so a file that grows cannot get past it).
std::string read_regular_file(const std::filesystem::path& path, std::string_view what, uint64_t max_bytes);

}  // namespace arpipe
