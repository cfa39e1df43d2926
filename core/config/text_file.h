// Reading a whole configuration-like text file (config, scene, board) with the reason it failed,
// so each loader words the error in its own terms and names the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace arpipe {

// Configs, scene and board files are hand-written: a few KB. 4 MiB leaves room for generated ones
// (long keyframe lists) while keeping a hostile file from filling memory before TOML parsing.
inline constexpr uint64_t kMaxTextFileBytes = uint64_t{4} << 20;

// The file's bytes, or nullopt with `why` set ("it is a directory", "it is a FIFO (named pipe),
// expected a regular file", the size limit, or the system's reason). Only regular files are read
// (core/config/regular_file.h).
std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why);

}  // namespace arpipe
