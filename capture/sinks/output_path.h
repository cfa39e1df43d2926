// Creating output locations and files for sinks, with errors that name the path and the config key.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string_view>

namespace arpipe {

// Creates dir (and parents). Throws std::runtime_error naming the directory and config key.
void create_output_directory(const std::filesystem::path& dir, std::string_view config_key);
// Creates the parent directory of a file path, same errors.
void create_parent_directory(const std::filesystem::path& file, std::string_view config_key);

// A file a sink writes to, created with its parent directory; closed (after a sync) when destroyed.
class OutputFile {
 public:
  // Throws std::runtime_error naming the path and config key when it cannot be created.
  OutputFile(const std::filesystem::path& path, std::string_view config_key);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  FILE* get() const { return file_; }
  // Pushes what was written to the disk (fflush + fsync); false on failure.
  bool sync() noexcept;

 private:
  FILE* file_ = nullptr;
};

}  // namespace arpipe
