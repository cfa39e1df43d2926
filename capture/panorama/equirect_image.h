// A 360° still in the equirectangular layout (core/environment/environment_layout.h), 8-bit sRGB,
// with a box-filtered pyramid built on demand (a view that never minifies needs none, and a video
// frame's pyramid is most of its cost past decoding), sampled along a direction: bilinear, wrapping across the seam
// (the left and right edges) and crossing the poles (the row above the top row is the top row
// half a turn round), so no direction has a seam or a pinch.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/config/panorama_config.h"

namespace arpipe {

class EquirectImage {
 public:
  // Largest panorama accepted: 16384 x 8192 (a 16K still), checked on the file's header first.
  static constexpr int kMaxWidth = 16384;
  static constexpr int kMaxSmallestLevelHeight = 8;  // the pyramid stops above this

  // What keeps width x height from being a panorama here (not 2:1, an odd height, wider than
  // kMaxWidth), or "" for none.
  static std::string shape_problem(int width, int height);

  // rgb: width x height x 3 bytes, row 0 at the top (the zenith); width = 2 height, both even.
  // Throws std::invalid_argument naming `name` for another shape.
  EquirectImage(std::vector<uint8_t> rgb, int width, int height, std::string name);

  // PNG or JPEG (sRGB as stored), Radiance .hdr or OpenEXR (linear radiance times hdr_scale,
  // clipped to [0, 1] and sRGB-encoded). Throws AssetError naming the file and what is wrong.
  static EquirectImage load(const std::filesystem::path& file, double hdr_scale);
  // The same for a layout: one image (mono), or the left eye's then the right eye's of a stereo
  // pair (each 2:1: the whole file 1:1 for top/bottom, 4:1 for left/right; Auto: by the shape).
  static std::vector<EquirectImage> load_eyes(const std::filesystem::path& file, double hdr_scale, PanoramaLayout layout);
  // Splits a whole image of the layout into its eyes (mono: itself). Throws std::invalid_argument
  // naming `name` for a shape the layout cannot hold (stereo_shape_problem()).
  static std::vector<EquirectImage> split(std::vector<uint8_t> rgb, int width, int height, PanoramaLayout layout,
                                          const std::string& name);
  // What keeps a whole width x height image from holding this layout's eyes, or "" for none.
  static std::string shape_problem(PanoramaLayout layout, int width, int height);

  // The levels the pyramid can have (each the 2 x 2 mean of the one above, while both sides stay
  // even and the height at least kMaxSmallestLevelHeight), and those built so far (level 0 at
  // least). sample() and texel() read built levels only.
  int levels() const { return possible_levels_; }
  int built_levels() const { return static_cast<int>(levels_.size()); }
  // Builds the levels below `count` not built yet (count is clamped to levels()).
  void build_levels(int count);

  int width(int level = 0) const { return levels_[0].width >> level; }
  int height(int level = 0) const { return levels_[0].height >> level; }
  const std::string& name() const { return name_; }

  // The bilinear sample at pixel position (u, v) of `level` (texel centres at integers, so level
  // 0 spans [-0.5, width - 0.5)), folded across the seam and the poles, rounded to 8 bits.
  inline void sample(int level, float u, float v, uint8_t out[3]) const;  // inline: the lookup's inner loop
  // The texel (x, y) of `level` after folding (any integers).
  const uint8_t* texel(int level, int x, int y) const;

 private:
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<uint8_t> rgb;
  };
  std::vector<Level> levels_;
  int possible_levels_ = 1;
  std::string name_;
};

inline void EquirectImage::sample(int level, float u, float v, uint8_t out[3]) const {
  const float fu = std::floor(u), fv = std::floor(v);
  const float ax = u - fu, ay = v - fv;
  const int x0 = static_cast<int>(fu), y0 = static_cast<int>(fv);
  const Level& l = levels_[static_cast<size_t>(level)];
  const uint8_t *a, *b, *c, *d;
  if (x0 >= 0 && y0 >= 0 && x0 + 1 < l.width && y0 + 1 < l.height) {  // nothing to fold: most taps
    a = l.rgb.data() + (size_t(y0) * size_t(l.width) + size_t(x0)) * 3;
    b = a + 3;
    c = a + size_t(l.width) * 3;
    d = c + 3;
  } else {
    a = texel(level, x0, y0);
    b = texel(level, x0 + 1, y0);
    c = texel(level, x0, y0 + 1);
    d = texel(level, x0 + 1, y0 + 1);
  }
  for (int k = 0; k < 3; ++k) {
    const float top = float(a[k]) + ax * (float(b[k]) - float(a[k]));
    const float bottom = float(c[k]) + ax * (float(d[k]) - float(c[k]));
    out[k] = static_cast<uint8_t>(top + ay * (bottom - top) + 0.5f);
  }
}

}  // namespace arpipe
