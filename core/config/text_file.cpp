// Whole text files through the regular-file-only reader, the failure turned into a reason.
#include "core/config/text_file.h"

#include "core/config/regular_file.h"

namespace arpipe {

std::optional<std::string> read_text_file(const std::filesystem::path& path, std::string& why) {
  try {
    return read_regular_file(path, "text file", kMaxTextFileBytes);
  } catch (const FileAccessError& e) {
    why = e.reason();
    return std::nullopt;
  }
}

}  // namespace arpipe
