#include "capture/panorama/panorama_light.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/environment/environment_layout.h"
#include "core/image/srgb.h"

namespace arpipe {
namespace {

// sRGB display value -> linear, per byte.
const std::array<double, 256>& linear_of_byte() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (size_t i = 0; i < 256; ++i) t[i] = srgb_decode(double(i) / 255);
    return t;
  }();
  return table;
}

}  // namespace

PanoramaLight::PanoramaLight(int width, int height, const Mat3& R_world_pano) : width_(width), height_(height) {
  if (const std::string why = EquirectImage::shape_problem(width, height); !why.empty())
    throw std::invalid_argument("PanoramaLight: " + why);
  block_ = (width + kMaxColumns - 1) / kMaxColumns;
  columns_ = (width + block_ - 1) / block_;
  rows_ = (height + block_ - 1) / block_;
  constexpr double pi = std::numbers::pi;
  weights_.resize(size_t(columns_) * size_t(rows_));
  for (int r = 0; r < rows_; ++r) {
    const int y0 = r * block_, y1 = std::min(height, y0 + block_);
    // The band of rows between polar angles pi y0 / H and pi y1 / H, and a block's share of it.
    const double band = std::cos(pi * y0 / height) - std::cos(pi * y1 / height);
    for (int c = 0; c < columns_; ++c) {
      const int x0 = c * block_, x1 = std::min(width, x0 + block_);
      const double solid_angle = 2 * pi * double(x1 - x0) / width * band;
      const Vec3 d = *environment_pixel_direction(EnvironmentLayout::Equirectangular, width, height, 0.5 * (x0 + x1 - 1),
                                                  0.5 * (y0 + y1 - 1));
      std::array<double, 9> y{};
      sh_basis(3, mat_mul(R_world_pano, d), y);
      for (size_t i = 0; i < 9; ++i) y[i] *= solid_angle;
      weights_[size_t(r) * size_t(columns_) + size_t(c)] = y;
    }
  }
}

template <class Texel>
ShRgb9 PanoramaLight::integrate(Texel texel, int taps_across) const {
  ShRgb9 sh{};
  for (int r = 0; r < rows_; ++r) {
    const int y0 = r * block_, y1 = std::min(height_, y0 + block_);
    for (int c = 0; c < columns_; ++c) {
      const int x0 = c * block_, x1 = std::min(width_, x0 + block_);
      Vec3 sum{0, 0, 0};
      int count = 0;
      if (taps_across <= 0 || taps_across >= block_) {
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) sum = sum + texel(x, y);
        count = (y1 - y0) * (x1 - x0);
      } else {
        // Taps at the centres of a taps_across x taps_across split of the block.
        for (int j = 0; j < taps_across; ++j)
          for (int i = 0; i < taps_across; ++i) {
            const int x = x0 + ((2 * i + 1) * (x1 - x0)) / (2 * taps_across);
            const int y = y0 + ((2 * j + 1) * (y1 - y0)) / (2 * taps_across);
            sum = sum + texel(x, y);
            ++count;
          }
      }
      const Vec3 mean = (1.0 / count) * sum;
      const std::array<double, 9>& w = weights_[size_t(r) * size_t(columns_) + size_t(c)];
      for (size_t i = 0; i < 9; ++i) sh[i] = sh[i] + w[i] * mean;
    }
  }
  return sh;
}

ShRgb9 PanoramaLight::project(const EquirectImage& image, int taps_across) const {
  if (image.width() != width_ || image.height() != height_)
    throw std::invalid_argument(fmt::format("PanoramaLight: a {} x {} image for a {} x {} grid", image.width(),
                                            image.height(), width_, height_));
  const std::array<double, 256>& linear = linear_of_byte();
  return integrate(
      [&](int x, int y) {
        const uint8_t* t = image.texel(0, x, y);
        return Vec3{linear[t[0]], linear[t[1]], linear[t[2]]};
      },
      taps_across);
}

ShRgb9 PanoramaLight::project(const HdrImage& image, double scale) const {
  if (image.width != width_ || image.height != height_)
    throw std::invalid_argument(fmt::format("PanoramaLight: a {} x {} image for a {} x {} grid", image.width, image.height,
                                            width_, height_));
  return integrate([&](int x, int y) { return scale * image.at(x, y); }, 0);
}

}  // namespace arpipe
