// A 360° still in the equirectangular layout (core/environment/environment_layout.h), 8-bit sRGB,
// with a box-filtered pyramid, sampled along a direction: bilinear, wrapping across the seam
// (the left and right edges) and crossing the poles (the row above the top row is the top row
// half a turn round), so no direction has a seam or a pinch.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace arpipe {

class EquirectImage {
 public:
  // Largest panorama accepted: 16384 x 8192 (a 16K still), checked on the file's header first.
  static constexpr int kMaxWidth = 16384;
  static constexpr int kMaxSmallestLevelHeight = 8;  // the pyramid stops above this

  // rgb: width x height x 3 bytes, row 0 at the top (the zenith); width = 2 height, both even.
  // Throws std::invalid_argument naming `name` for another shape.
  EquirectImage(std::vector<uint8_t> rgb, int width, int height, std::string name);

  // PNG or JPEG (sRGB as stored), Radiance .hdr or OpenEXR (linear radiance times hdr_scale,
  // clipped to [0, 1] and sRGB-encoded). Throws AssetError naming the file and what is wrong.
  static EquirectImage load(const std::filesystem::path& file, double hdr_scale);

  int levels() const { return static_cast<int>(levels_.size()); }
  int width(int level = 0) const { return levels_[static_cast<size_t>(level)].width; }
  int height(int level = 0) const { return levels_[static_cast<size_t>(level)].height; }
  const std::string& name() const { return name_; }

  // The bilinear sample at pixel position (u, v) of `level` (texel centres at integers, so level
  // 0 spans [-0.5, width - 0.5)), folded across the seam and the poles, rounded to 8 bits.
  void sample(int level, float u, float v, uint8_t out[3]) const;
  // The texel (x, y) of `level` after folding (any integers).
  const uint8_t* texel(int level, int x, int y) const;

 private:
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgb;
  };
  std::vector<Level> levels_;
  std::string name_;
};

}  // namespace arpipe
