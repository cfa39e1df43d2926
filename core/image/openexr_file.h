// OpenEXR light-probe files through the OpenEXR library: read any RGB (or luminance) scanline or
// tiled file into linear float RGB, write half-float RGB; library errors become AssetError.
#pragma once

#include <filesystem>

#include "core/image/hdr_image.h"

namespace arpipe {

// Reads the data window (its offset does not matter; its size must be 1..32768 per side and at
// most 2^28 pixels). Files with R, G or B channels are read as float (half, float or uint
// converted by the library; a missing channel reads 0); others (Y, Y/RY/BY) through the library's
// RGBA interface. Texels are not checked here (see check_hdr_texels).
HdrImage read_openexr(const std::filesystem::path& file);

// Writes half-float RGB (ZIP compression) through a temporary file renamed into place. Throws
// AssetError for NaN, infinite or negative texels and for values above half's maximum (65504).
void write_openexr(const std::filesystem::path& file, const HdrImage& image);

}  // namespace arpipe
