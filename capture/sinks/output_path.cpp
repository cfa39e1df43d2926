#include "capture/sinks/output_path.h"

#include <fmt/format.h>

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace arpipe {

void create_output_directory(const std::filesystem::path& dir, std::string_view config_key) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw std::runtime_error(fmt::format("{} (config {}): cannot create the output directory: {}", dir.string(),
                                         config_key, ec ? ec.message() : "a file of that name is in the way"));
}

void create_parent_directory(const std::filesystem::path& file, std::string_view config_key) {
  if (file.has_parent_path()) create_output_directory(file.parent_path(), config_key);
}

OutputFile::OutputFile(const std::filesystem::path& path, std::string_view config_key) {
  create_parent_directory(path, config_key);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_)
    throw std::runtime_error(
        fmt::format("{} (config {}): cannot open for writing: {}", path.string(), config_key, std::strerror(errno)));
}

OutputFile::~OutputFile() {
  sync();
  std::fclose(file_);
}

bool OutputFile::sync() noexcept { return std::fflush(file_) == 0 && ::fsync(fileno(file_)) == 0; }

}  // namespace arpipe
