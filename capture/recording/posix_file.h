// A file descriptor owned by RAII, with the positioned reads and writes and the fsync that
// crash-safe appending needs (std::fstream can neither fsync nor report what was written).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace arpipe {

class PosixFile {
 public:
  // Read opens regular files only (core/config/regular_file.h: no FIFO, device or /proc);
  // CreateNew fails when the file exists (O_EXCL).
  enum class Mode { Read, CreateNew };

  PosixFile() = default;
  // Throws std::system_error (FileAccessError for Read) whose what() names the path.
  PosixFile(const std::filesystem::path& path, Mode mode);
  ~PosixFile();
  PosixFile(PosixFile&& other) noexcept;
  PosixFile& operator=(PosixFile&& other) noexcept;
  PosixFile(const PosixFile&) = delete;
  PosixFile& operator=(const PosixFile&) = delete;

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }
  // Writes all bytes at offset (retrying short writes); throws std::system_error naming the path.
  void write_at(uint64_t offset, const void* data, size_t size);
  // Reads exactly size bytes at offset; false when the file ends first. Throws on I/O errors.
  bool read_at(uint64_t offset, void* data, size_t size) const;
  // Reads up to size bytes at offset; returns how many (0 at the end of the file). Throws on I/O errors.
  size_t read_some(uint64_t offset, void* data, size_t size) const;
  uint64_t size() const;
  void truncate(uint64_t size);
  void sync();
  void close();

  // fsync()s a directory so that the names of files created in it survive a power loss.
  static void sync_directory(const std::filesystem::path& dir);

 private:
  int fd_ = -1;
  std::filesystem::path path_;
};

}  // namespace arpipe
