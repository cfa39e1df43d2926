// Reading an untrusted asset's files: only regular files, never more than a stated limit, and an
// asset's external references only inside the asset's own folder (symlinks resolved).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace arpipe {

// The whole of `path` when it is a regular file (after symlinks) of at most `limit` bytes; else
// nullopt with the reason in *why (no path in it: the caller names the file). A FIFO, device or
// directory is refused without blocking, and nothing is read from a file over the limit.
std::optional<std::vector<unsigned char>> read_asset_file(const std::filesystem::path& path, uint64_t limit,
                                                          std::string* why);

// `reference` (a path relative to `folder`, e.g. a glTF buffer's decoded URI) resolved with every
// symlink followed, when the result exists and lies inside `folder` (itself canonical: see
// canonical_folder); else nullopt with the reason in *why. An absolute `reference` is taken as
// relative to `folder`, as glTF URIs are.
std::optional<std::filesystem::path> resolve_inside_folder(const std::filesystem::path& folder,
                                                           const std::string& reference, std::string* why);

// The canonical folder holding `file` (the working directory for a bare file name); nullopt with
// the reason in *why when it cannot be resolved.
std::optional<std::filesystem::path> canonical_folder(const std::filesystem::path& file, std::string* why);

}  // namespace arpipe
