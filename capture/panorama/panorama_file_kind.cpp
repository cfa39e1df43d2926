#include "capture/panorama/panorama_file_kind.h"

#include <algorithm>
#include <cctype>
#include <string>

namespace arpipe {

PanoramaFileKind panorama_file_kind(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".hdr" || ext == ".exr") return PanoramaFileKind::Hdr;
  if (ext == ".mp4" || ext == ".m4v" || ext == ".mov" || ext == ".mkv" || ext == ".webm") return PanoramaFileKind::Video;
  return PanoramaFileKind::Picture;
}

}  // namespace arpipe
