// Defocus and vignetting of the simulated lens (lens_optics.h).
#include "capture/sim/lens_optics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace arpipe::sim {

namespace {

// The disc's chord half-height at horizontal offset x: sqrt(r^2 - x^2), 0 outside.
double half_chord(double r, double x) { return std::abs(x) >= r ? 0.0 : std::sqrt(r * r - x * x); }

// The integral of half_chord from 0 to x (|x| <= r): (x h(x) + r^2 asin(x / r)) / 2.
double chord_integral(double r, double x) {
  const double t = std::clamp(x / r, -1.0, 1.0);
  return 0.5 * (x * half_chord(r, x) + r * r * std::asin(t));
}

// Area of the disc of radius r (centred at 0) inside [x0, x1] x [y0, y1], in closed form: the
// integral over x of the overlap of [y0, y1] with the chord [-h(x), h(x)], split where h(x)
// crosses y0 or y1 (or -h(x) does), so that on each piece the overlap's ends are each a constant
// or +-h(x), whose integrals are exact.
double disc_area_in_box(double r, double x0, double x1, double y0, double y1) {
  const double a = std::max(x0, -r), b = std::min(x1, r);
  if (!(b > a) || !(y1 > y0)) return 0;
  std::vector<double> cuts{a, b};
  for (const double y : {y0, y1})
    if (std::abs(y) < r) {
      const double x = std::sqrt(r * r - y * y);
      if (x > a && x < b) cuts.push_back(x);
      if (-x > a && -x < b) cuts.push_back(-x);
    }
  std::sort(cuts.begin(), cuts.end());
  double area = 0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double p = cuts[k], q = cuts[k + 1];
    if (!(q > p)) continue;
    const double h = half_chord(r, 0.5 * (p + q));
    const double chord = chord_integral(r, q) - chord_integral(r, p);  // integral of h over [p, q]
    const double upper = y1 < h ? y1 * (q - p) : chord;
    const double lower = y0 > -h ? y0 * (q - p) : -chord;
    if (std::min(y1, h) > std::max(y0, -h)) area += upper - lower;
  }
  return area;
}

}  // namespace

DiscKernel disc_kernel(double diameter_px) {
  if (!(diameter_px >= 0) || !std::isfinite(diameter_px))
    throw std::invalid_argument(fmt::format("camera.optics.defocus_px must be a finite number >= 0, got {}", diameter_px));
  DiscKernel kernel;
  const double r = diameter_px / 2;
  // Pixel k's square reaches |k| - 1/2 from the centre: it meets the disc when that is below r.
  kernel.half_size = r <= 0.5 ? 0 : int(std::ceil(r - 0.5));
  const int side = 2 * kernel.half_size + 1;
  kernel.weights.assign(size_t(side) * size_t(side), 0.0);
  if (kernel.half_size == 0) {
    kernel.weights[0] = 1;
    return kernel;
  }
  double total = 0;
  for (int j = -kernel.half_size; j <= kernel.half_size; ++j)
    for (int i = -kernel.half_size; i <= kernel.half_size; ++i) {
      const double w = disc_area_in_box(r, i - 0.5, i + 0.5, j - 0.5, j + 0.5);
      kernel.weights[size_t(j + kernel.half_size) * size_t(side) + size_t(i + kernel.half_size)] = w;
      total += w;
    }
  for (double& w : kernel.weights) w /= total;  // total is pi r^2 to rounding
  return kernel;
}

void apply_defocus(const DiscKernel& kernel, RadianceImage& image) {
  if (kernel.half_size == 0) return;
  const int width = image.width, height = image.height, k = kernel.half_size, side = 2 * k + 1;
  std::vector<float> out(image.rgb.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum[3] = {0, 0, 0};
      for (int j = -k; j <= k; ++j) {
        const int yy = std::clamp(y + j, 0, height - 1);
        const double* row = &kernel.weights[size_t(j + k) * size_t(side)];
        for (int i = -k; i <= k; ++i) {
          const double w = row[i + k];
          if (w == 0) continue;
          const float* p = &image.rgb[(size_t(yy) * size_t(width) + size_t(std::clamp(x + i, 0, width - 1))) * 3];
          sum[0] += w * p[0];
          sum[1] += w * p[1];
          sum[2] += w * p[2];
        }
      }
      float* o = &out[(size_t(y) * size_t(width) + size_t(x)) * 3];
      for (int c = 0; c < 3; ++c) o[c] = float(sum[c]);
    }
  image.rgb.swap(out);
}

double relative_illumination(double cos_theta, double strength) {
  const double c = std::max(0.0, std::min(1.0, cos_theta));
  const double c2 = c * c;
  return (1 - strength) + strength * c2 * c2;
}

LensOptics::LensOptics(const SimOptics& optics, const CameraRayGrid& rays, int width, int height)
    : defocus_(optics.defocus_px > 0), vignetting_(optics.vignetting > 0), width_(width), height_(height) {
  if (defocus_) kernel_ = disc_kernel(optics.defocus_px);
  if (!vignetting_) return;
  if (!(optics.vignetting <= 1))
    throw std::invalid_argument(fmt::format("camera.optics.vignetting must be in [0, 1], got {}", optics.vignetting));
  illumination_.assign(size_t(width) * size_t(height), 1.0f);
  std::array<double, 3> dir{};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (rays.ray(x, y, dir))
        illumination_[size_t(y) * size_t(width) + size_t(x)] = float(relative_illumination(dir[2], optics.vignetting));
}

void LensOptics::apply(RadianceImage& image) const {
  if (image.width != width_ || image.height != height_)
    throw std::invalid_argument(fmt::format("lens optics: a {}x{} image for a {}x{} lens", image.width, image.height,
                                            width_, height_));
  if (defocus_) apply_defocus(kernel_, image);
  if (vignetting_)
    for (size_t p = 0; p < illumination_.size(); ++p)
      for (size_t c = 0; c < 3; ++c) image.rgb[p * 3 + c] *= illumination_[p];
}

}  // namespace arpipe::sim
