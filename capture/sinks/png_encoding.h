// A composited RGB24 frame encoded as PNG in memory (OpenCV's libpng): the PNG sink's files and the
// live outputs' snapshots, the same bytes for the same frame and level.
#pragma once

#include <cstdint>
#include <vector>

#include "core/frame.h"

namespace arpipe {

// compression: zlib level 0-9; 1 is OpenCV's own default (its fast filter and strategy), which
// is left unnamed so that its PNGs keep their bytes. Throws std::runtime_error when the encoder
// refuses the frame.
std::vector<uint8_t> encode_png(const Frame& rgb, int compression = 1);

}  // namespace arpipe
