// The lens's effects on the simulated image, in linear light before the sensor: defocus (a uniform
// disc point-spread function, the circle of confusion) and vignetting (relative illumination
// falling off with the field angle). SimOptics (sim_scene.h) holds the scene's numbers.
#pragma once

#include <vector>

#include "capture/sim/camera_ray_grid.h"
#include "capture/sim/frame_renderer.h"
#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

// A square kernel of side 2 half_size + 1, row-major, summing to 1: tap (i, j) (offsets from the
// centre, -half_size..half_size) weighs the area of the disc of diameter diameter_px, centred on
// the pixel centre, that falls in pixel (i, j)'s unit square, divided by the disc's area. A disc
// inside the centre pixel (diameter <= 1) gives the identity.
struct DiscKernel {
  int half_size = 0;
  std::vector<double> weights;
  double at(int i, int j) const { return weights[size_t(j + half_size) * size_t(2 * half_size + 1) + size_t(i + half_size)]; }
};
DiscKernel disc_kernel(double diameter_px);

// Convolves an RGB radiance image with the kernel; the scene beyond the image's edge is taken to
// continue as its edge pixels (clamped coordinates), so a uniform image stays uniform.
void apply_defocus(const DiscKernel& kernel, RadianceImage& image);

// The relative illumination (1 - strength) + strength cos^4(theta) of a ray whose unit camera-frame
// direction has z component cos_theta (clamped at 0 beyond 90 degrees).
double relative_illumination(double cos_theta, double strength);

// One camera's optics: its kernel and its per-pixel relative illumination (from the rays of each
// pixel's centre, CameraRayGrid's unprojection; 1 where the lens cannot unproject).
class LensOptics {
 public:
  LensOptics(const SimOptics& optics, const CameraRayGrid& rays, int width, int height);
  bool active() const { return defocus_ || vignetting_; }
  // Defocus, then vignetting, on one eye's width x height radiance image.
  void apply(RadianceImage& image) const;
  const std::vector<float>& illumination() const { return illumination_; }

 private:
  bool defocus_ = false;
  bool vignetting_ = false;
  DiscKernel kernel_;
  int width_ = 0;
  int height_ = 0;
  std::vector<float> illumination_;  // per pixel, row-major; empty without vignetting
};

}  // namespace arpipe::sim
