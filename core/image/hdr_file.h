// Reading an HDR light-probe image whatever its format (Radiance .hdr or OpenEXR, told apart by
// the magic bytes), and the texel check every HDR input goes through (finite, non-negative).
#pragma once

#include <filesystem>
#include <string>

#include "core/image/hdr_image.h"

namespace arpipe {

// Reads a Radiance .hdr ("#?") or OpenEXR (76 2f 31 01) file and checks its texels; anything else,
// or a bad texel, throws AssetError naming the file.
HdrImage read_hdr_image(const std::filesystem::path& file);

// Throws AssetError naming `name`, the pixel (x, y), the channel and the value for the first NaN,
// infinite or negative texel (and for an rgb array whose size is not 3 * width * height).
void check_hdr_texels(const HdrImage& image, const std::string& name);

}  // namespace arpipe
