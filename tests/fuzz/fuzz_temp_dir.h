// A private scratch directory per fuzzing process (in /dev/shm when it exists, so file-based
// loaders are fed from memory) and writing one input into it as a file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace arpipe::fuzz {

// Created on first use, removed at exit; the same directory for the life of the process.
const std::filesystem::path& temp_dir();

// Writes `size` bytes to temp_dir() / name (replacing it) and returns that path. Aborts when the
// file cannot be written: the harness, not the parser, would be broken.
std::filesystem::path write_temp_file(std::string_view name, const uint8_t* data, size_t size);

}  // namespace arpipe::fuzz
