// A file a sink appends to that a new run replaces only once it is up (written under a temporary
// name, renamed over the old one by commit()) and that holds whole records only (lines, frames).
#pragma once

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

namespace arpipe {

class OutputFile {
 public:
  // A regular file (or none yet) at path is written under temporary_name(path) until commit(); a
  // symlink is followed. A FIFO, socket or device is opened and written directly (nothing to
  // replace). Creates the parent directory. Throws std::runtime_error naming the path and config key.
  OutputFile(const std::filesystem::path& path, std::string_view config_key);
  // Not committed: removes the temporary, and the previous output stays as it was (a start that
  // failed). Committed: syncs and closes.
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // The run is up: renames this run's file over the previous output (once; later calls do nothing).
  // Returns false with the reason when the rename fails; this run's output then stays under its
  // temporary name (temporary()) and is kept.
  bool commit(std::string& error) noexcept;
  bool committed() const { return committed_; }

  // Appends one record made of parts, all or nothing: returns 0, or the errno of the failed write,
  // after cutting a regular file back to the end of its last whole record. A stream (FIFO, socket)
  // cannot be cut back; a broken pipe (EPIPE) is returned without raising SIGPIPE. A FIFO is then
  // closed, dropping what its reader left unread, and opened again when a new reader has come.
  int append(std::initializer_list<std::span<const uint8_t>> parts) noexcept;

  bool is_regular() const { return regular_; }
  uint64_t size() const { return end_; }  // bytes of whole records (regular files)
  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& temporary() const { return temporary_; }
  // Pushes what was written to the disk; false on failure.
  bool sync() noexcept;

 private:
  std::filesystem::path path_;       // the output (a symlink resolved)
  std::filesystem::path temporary_;  // where this run writes until commit (regular files)
  int fd_ = -1;
  bool regular_ = true;
  bool pipe_like_ = false;           // FIFO or socket: a reader that leaves raises SIGPIPE
  bool fifo_ = false;                // reopened after its reader left (fd_ = -1 until then)
  bool committed_ = false;
  bool cut_back_pending_ = false;    // a failed write could not be cut back yet
  uint64_t end_ = 0;                 // end of the last whole record
};

}  // namespace arpipe
