// Reading an untrusted asset's files: only regular files, never more than a stated limit, and an
// asset's external references only inside the asset's own folder (symlinks resolved).
#include "core/scene/asset_file.h"

#include "core/config/regular_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <system_error>

namespace arpipe {

namespace fs = std::filesystem;

std::optional<std::vector<unsigned char>> read_asset_file(const fs::path& path, uint64_t limit, std::string* why) {
  // The one regular-file rule of the project (core/config/regular_file.h): no FIFO, device,
  // directory, /proc or /sys, no blocking on open, reading stops at the limit.
  try {
    const std::string text = read_regular_file(path, "asset file", limit);
    return std::vector<unsigned char>(text.begin(), text.end());
  } catch (const FileAccessError& error) {
    *why = error.action_and_reason();
    return std::nullopt;
  } catch (const std::bad_alloc&) {
    *why = "out of memory while reading it";
    return std::nullopt;
  }
}

std::optional<fs::path> canonical_folder(const fs::path& file, std::string* why) {
  const fs::path parent = file.parent_path();
  std::error_code error;
  fs::path folder = fs::canonical(parent.empty() ? fs::path(".") : parent, error);
  if (error) {
    *why = fmt::format("cannot resolve its folder: {}", error.message());
    return std::nullopt;
  }
  return folder;
}

std::optional<fs::path> resolve_inside_folder(const fs::path& folder, const std::string& reference, std::string* why) {
  if (reference.empty() || reference.find('\0') != std::string::npos) {
    *why = "an empty name or one with a NUL byte";
    return std::nullopt;
  }
  // As glTF URIs are joined: folder + "/" + reference, also for a reference starting with '/'.
  std::error_code error;
  const fs::path resolved = fs::canonical(fs::path(folder.string() + "/" + reference), error);
  if (error) {
    *why = fmt::format("cannot open: {}", error.message());
    return std::nullopt;
  }
  // Component by component: "/a/bc" is not inside "/a/b".
  auto [in_folder, in_resolved] = std::mismatch(folder.begin(), folder.end(), resolved.begin(), resolved.end());
  if (in_folder != folder.end() || in_resolved == resolved.end()) {
    *why = fmt::format("resolves to a file outside the asset's folder {} (references must stay inside it)",
                       folder.string());
    return std::nullopt;
  }
  return resolved;
}

}  // namespace arpipe
