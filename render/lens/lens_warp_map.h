// The map that bends a pinhole picture into the real lens's picture (render.lens = "map"): for
// every pixel of the lens image, where its ray meets an enlarged pinhole canvas. Pure CPU, mrcal.
#pragma once

#include <string>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

// Rays further off the optical axis than this need a pinhole canvas too large to be worth it
// (tan 75 deg = 3.7 focal lengths each side); such lenses are refused.
inline constexpr double kMaxOffAxisDeg = 75.0;

// The pinhole camera that the virtual objects are drawn with: the lens model's core fx, fy times
// the canvas scale, with the principal point moved so that the canvas holds every ray of the lens
// image.
struct PinholeCanvas {
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;
  int width = 0;
  int height = 0;

  CameraModel model() const { return CameraModel::pinhole(fx, fy, cx, cy, width, height); }
};

// Canvas pixels per pinhole-core pixel (render.lens_canvas_scale) that the config accepts.
inline constexpr double kMinCanvasScale = 1.0;
inline constexpr double kMaxCanvasScale = 4.0;

class LensWarpMap {
 public:
  // Unprojects every pixel centre with mrcal (on up to 4 threads: mrcal's unprojection is an
  // iterative solve, ~300 ms per 640x480 image on one core here). canvas_scale: canvas pixels per
  // pinhole-core pixel (more samples per image pixel for straight edges, at its square in cost).
  // Throws RenderError naming the model when it has no pinhole core, when mrcal cannot unproject a
  // pixel, when a pixel's ray does not project back onto it (the distortion folds over), or when
  // a ray lies more than kMaxOffAxisDeg off the axis. LENSMODEL_PINHOLE gives the identity map
  // (no canvas, no warp, whatever the scale).
  explicit LensWarpMap(const CameraModel& model, double canvas_scale = 1.0);

  const std::string& lensmodel() const { return lensmodel_; }
  int width() const { return width_; }    // of the lens image
  int height() const { return height_; }
  bool identity() const { return identity_; }
  const PinholeCanvas& canvas() const { return canvas_; }  // the model itself for the identity
  // Canvas pixel coordinates (pixel centres at integers, as mrcal's) of the ray through the centre
  // of lens pixel (x, y); two floats per pixel, row-major; empty for the identity.
  const std::vector<float>& canvas_xy() const { return canvas_xy_; }
  Vec2 at(int x, int y) const;
  // The longest step on the canvas between the map points of neighbouring pixels (1 for the identity).
  double max_texels_per_pixel() const { return max_texels_per_pixel_; }
  // How far from a pixel's map point the warp's samples may lie, in canvas texels along each
  // axis: taps within a quarter pixel each way along both pixel axes (lens_warp_pass.cpp).
  double tap_reach() const { return 0.5 * max_texels_per_pixel_; }

  // The canvas pixels that the warp reads for image_rect's pixels (each tap within tap_reach() of
  // the map point, each reading the 2x2 texels around it), with one texel to spare, clipped to the
  // canvas. The extremes of a map that does not fold lie on the rectangle's border, so only that
  // is scanned.
  PixelRect canvas_rect_for(const PixelRect& image_rect) const;

 private:
  std::string lensmodel_;
  int width_ = 0;
  int height_ = 0;
  bool identity_ = false;
  PinholeCanvas canvas_;
  std::vector<float> canvas_xy_;
  double max_texels_per_pixel_ = 1;
};

// The checks of the constructor on the border of the image only (a few thousand unprojections):
// refuses a lens before streaming starts without building the whole map.
void check_lens_warpable(const CameraModel& model);

}  // namespace arpipe
