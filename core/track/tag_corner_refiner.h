// Sub-pixel refinement of a detected tag's four corners: each border edge is located from the
// linear-light intensity profile across it, and the edges are intersected undistorted.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/geometry/camera_model.h"
#include "core/pixel_format.h"

namespace arpipe {

// Why: Debian's libapriltag 3.3 samples its edge refinement at integer positions (fixed upstream in
// 2024, PR #346) and, like any threshold on gamma-encoded values, puts a blurred edge on the dark
// side. On rendered sRGB tags its corners sit ~0.2 px inside the true ones, i.e. every tag looks
// 0.4% too small and too far. Locating edges in linear light, at full resolution, removes both.
class TagCornerRefiner {
 public:
  // grey_encoding: the pixel format the grey bytes came from. YUYV and NV12 luma is BT.601 limited
  // range (16-235); GREY and RGB24-derived luma are full range. Both are decoded as sRGB.
  explicit TagCornerRefiner(PixelFormat grey_encoding = PixelFormat::GREY);

  // corners: libapriltag order (bottom-left, bottom-right, top-right, top-left), pixels, as detected.
  // border_cells: how many code cells the detected square spans (family width_at_border), which
  // bounds how far from an edge one may sample without leaving the border. Returns false, leaving
  // corners untouched, when the tag is too small or an edge cannot be located.
  // normalized, when given, receives the refined corners undistorted (x/z, y/z): the intersections
  // the pixels were projected from.
  bool refine(const uint8_t* grey, int width, int height, size_t stride, const CameraModel& camera,
              int border_cells, std::array<Vec2, 4>& corners, std::array<Vec2, 4>* normalized = nullptr) const;

 private:
  std::array<float, 256> linear_{};
};

}  // namespace arpipe
