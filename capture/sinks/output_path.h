// Output locations of the sinks: directories created with errors that name the path and config key,
// temporary names beside an output (replaced by rename), and whole-file writes that never leave a partial file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>

namespace arpipe {

// Creates dir (and parents). Throws std::runtime_error naming the directory and config key.
void create_output_directory(const std::filesystem::path& dir, std::string_view config_key);
// Creates the parent directory of a file path, same errors.
void create_parent_directory(const std::filesystem::path& file, std::string_view config_key);

// "<dir>/.<name>.new-<pid>": where this process writes `path` before renaming it over `path`. In the
// same directory, so that the rename is atomic; hidden, and named by the process that owns it.
std::filesystem::path temporary_name(const std::filesystem::path& path);

// Removes temporaries in dir (named as temporary_name makes them) left by processes that no longer
// run (a crash or kill -9 between writing and renaming), for the outputs whose names `ours` accepts.
void remove_stale_temporaries(const std::filesystem::path& dir, const std::function<bool(std::string_view)>& ours) noexcept;

// fsync()s a directory, so that a rename in it survives a power loss; false on failure.
bool sync_directory(const std::filesystem::path& dir) noexcept;

// Writes bytes as the whole new content of path: to its temporary name, synced, then renamed over
// path. On failure the temporary is removed, path stays as it was, and the errno is returned (0 = written).
int replace_file(const std::filesystem::path& path, std::span<const uint8_t> bytes) noexcept;

}  // namespace arpipe
