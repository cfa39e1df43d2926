// Image error measures over a mask (see image_quality.h).
#include "core/image/image_quality.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arpipe {
namespace {

void check_sizes(const RgbView& a, const RgbView& b, std::span<const uint8_t> mask) {
  const size_t pixels = size_t(a.width) * size_t(a.height);
  if (a.width != b.width || a.height != b.height || a.data.size() < pixels * 3 || b.data.size() < pixels * 3 ||
      mask.size() != pixels)
    throw std::invalid_argument("image comparison: the images and the mask differ in size");
}

std::vector<double> luma(const RgbView& image) {
  std::vector<double> out(size_t(image.width) * image.height);
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = 0.299 * image.data[3 * i] + 0.587 * image.data[3 * i + 1] + 0.114 * image.data[3 * i + 2];
  return out;
}

}  // namespace

double masked_psnr(const RgbView& a, const RgbView& b, std::span<const uint8_t> mask) {
  check_sizes(a, b, mask);
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    for (size_t c = 0; c < 3; ++c) {
      const double d = double(a.data[3 * i + c]) - double(b.data[3 * i + c]);
      sum += d * d;
    }
    count += 3;
  }
  if (count == 0) return std::numeric_limits<double>::quiet_NaN();
  if (sum == 0) return std::numeric_limits<double>::infinity();
  return 10 * std::log10(255.0 * 255.0 / (sum / double(count)));
}

double masked_ssim(const RgbView& a, const RgbView& b, std::span<const uint8_t> mask) {
  check_sizes(a, b, mask);
  constexpr int kRadius = 5;
  constexpr double kSigma = 1.5;
  constexpr double kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);
  std::array<double, 2 * kRadius + 1> weight{};
  for (int k = -kRadius; k <= kRadius; ++k) weight[size_t(k + kRadius)] = std::exp(-0.5 * k * k / (kSigma * kSigma));
  const std::vector<double> x = luma(a), y = luma(b);
  const int w = a.width, h = a.height;
  double total = 0;
  size_t windows = 0;
  for (int cy = 0; cy < h; ++cy)
    for (int cx = 0; cx < w; ++cx) {
      if (!mask[size_t(cy) * w + cx]) continue;
      double sw = 0, mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
      for (int dy = -kRadius; dy <= kRadius; ++dy) {
        const int py = cy + dy;
        if (py < 0 || py >= h) continue;
        for (int dx = -kRadius; dx <= kRadius; ++dx) {
          const int px = cx + dx;
          if (px < 0 || px >= w) continue;
          const double g = weight[size_t(dy + kRadius)] * weight[size_t(dx + kRadius)];
          const double u = x[size_t(py) * w + px], v = y[size_t(py) * w + px];
          sw += g;
          mx += g * u;
          my += g * v;
          xx += g * u * u;
          yy += g * v * v;
          xy += g * u * v;
        }
      }
      mx /= sw;
      my /= sw;
      const double vx = std::max(0.0, xx / sw - mx * mx), vy = std::max(0.0, yy / sw - my * my);
      const double cov = xy / sw - mx * my;
      total += ((2 * mx * my + kC1) * (2 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
      ++windows;
    }
  return windows ? total / double(windows) : std::numeric_limits<double>::quiet_NaN();
}

std::vector<uint8_t> dilate_mask(std::span<const uint8_t> mask, int width, int height, int radius) {
  std::vector<uint8_t> rows(mask.size(), 0), out(mask.size(), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      bool any = false;
      for (int d = -radius; d <= radius && !any; ++d) {
        const int px = x + d;
        any = px >= 0 && px < width && mask[size_t(y) * width + px];
      }
      rows[size_t(y) * width + x] = any;
    }
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      bool any = false;
      for (int d = -radius; d <= radius && !any; ++d) {
        const int py = y + d;
        any = py >= 0 && py < height && rows[size_t(py) * width + x];
      }
      out[size_t(y) * width + x] = any;
    }
  return out;
}

}  // namespace arpipe
