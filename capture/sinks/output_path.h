// Creating output locations for sinks, with errors that name the path and the config key.
#pragma once

#include <filesystem>
#include <string_view>

namespace arpipe {

// Creates dir (and parents). Throws std::runtime_error naming the directory and config key.
void create_output_directory(const std::filesystem::path& dir, std::string_view config_key);
// Creates the parent directory of a file path, same errors.
void create_parent_directory(const std::filesystem::path& file, std::string_view config_key);

}  // namespace arpipe
