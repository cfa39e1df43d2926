// HdrImage: a linear-light RGB float image as read from a Radiance .hdr or OpenEXR file, the
// common in-memory form of light probes (row 0 at the top, 3 floats per pixel).
#pragma once

#include <cstdint>

#include <cstddef>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

// What an HDR file may hold at most, whatever its header claims (the readers refuse more): a side of
// 32768 pixels and 2^28 pixels (3 GiB of floats).
constexpr int kMaxHdrSide = 32768;
constexpr int64_t kMaxHdrPixels = int64_t{1} << 28;

struct HdrImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear RGB, 3 floats per pixel, row-major, row 0 at the top

  Vec3 at(int x, int y) const {
    const size_t i = 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

}  // namespace arpipe
