// A panorama as the whole light around the view (light.source = "panorama"; seed 003's suggested
// image-based lighting): its radiance projected onto 3 spherical-harmonic bands in the world frame,
// for the light stage's existing SH path. An 8-bit panorama's values are sRGB display values, so
// its radiance is their linear value (a white surface lit by a uniform panorama of value v shows v);
// what is clipped in it (a sun) is light lost. An HDR still's radiance is the file's times hdr_scale,
// unclipped.
#pragma once

#include <array>
#include <vector>

#include "capture/panorama/equirect_image.h"
#include "core/geometry/vec.h"
#include "core/image/hdr_image.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

class PanoramaLight {
 public:
  // The grid of blocks at most kMaxColumns x kMaxColumns / 2 that panoramas of width x height are
  // integrated over, each block's basis values at its centre's world direction (R_world_pano: the
  // panorama's placement) times its exact solid angle. Throws std::invalid_argument for a shape
  // EquirectImage refuses.
  static constexpr int kMaxColumns = 256;
  PanoramaLight(int width, int height, const Mat3& R_world_pano);

  // Each block's mean linear value, from every texel (taps_across = 0: a still, once) or from an
  // evenly spread taps_across x taps_across subset (a video, every frame), times the block's
  // weights. The image must have the constructor's size.
  ShRgb9 project(const EquirectImage& image, int taps_across = 0) const;
  // The same integration of an HDR image's radiance times scale, every texel.
  ShRgb9 project(const HdrImage& image, double scale) const;

  int block_side() const { return block_; }

 private:
  template <class Texel>
  ShRgb9 integrate(Texel texel, int taps_across) const;
  int width_ = 0, height_ = 0, block_ = 1, columns_ = 0, rows_ = 0;
  std::vector<std::array<double, 9>> weights_;  // per block, row-major: y_i(centre) * solid angle
};

}  // namespace arpipe
