// Reading a whole configuration-like text file (config, scene, board) with the reason it failed,
// so each loader words the error in its own terms and names the file.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace arpipe {

// The file's bytes, or nullopt with `why` set ("it is a directory", or the system's reason).
std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why);

}  // namespace arpipe
