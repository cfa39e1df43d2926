// What a panorama file holds, told by its name's extension (any case): the still loader and the
// source choose their reader by it; the readers themselves check the content.
#pragma once

#include <filesystem>

namespace arpipe {

enum class PanoramaFileKind {
  Picture,  // PNG or JPEG (and anything not below: the picture reader names what it is not)
  Hdr,      // .hdr (Radiance) or .exr (OpenEXR)
  Video,    // .mp4, .m4v, .mov, .mkv, .webm
};

PanoramaFileKind panorama_file_kind(const std::filesystem::path& file);

}  // namespace arpipe
