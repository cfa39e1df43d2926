#include "core/image/bayer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "core/image/srgb.h"

namespace arpipe {

namespace {

// OpenCV names a Bayer pattern by the second row's second and third pixels, not by the top-left
// cell as V4L2 does: V4L2's RGGB (row 1: G B G B) is OpenCV's "BG". tests/core/image/bayer_test
// checks each order with a mosaic of a known colour.
int opencv_demosaic_code(BayerOrder order) {
  switch (order) {
    case BayerOrder::RGGB: return cv::COLOR_BayerBG2RGB_EA;
    case BayerOrder::BGGR: return cv::COLOR_BayerRG2RGB_EA;
    case BayerOrder::GRBG: return cv::COLOR_BayerGB2RGB_EA;
    case BayerOrder::GBRG: return cv::COLOR_BayerGR2RGB_EA;
  }
  return cv::COLOR_BayerBG2RGB_EA;
}

// Linear [0, 1] in 65536 steps to 8-bit sRGB: fine enough that the steepest part of the curve
// (slope 12.92 near black) moves by under 0.06 of a code per step.
const std::array<uint8_t, 65536>& srgb_lut() {
  static const std::array<uint8_t, 65536> lut = [] {
    std::array<uint8_t, 65536> t{};
    for (size_t i = 0; i < t.size(); ++i) t[i] = uint8_t(std::lround(srgb_encode(double(i) / 65535.0) * 255.0));
    return t;
  }();
  return lut;
}

}  // namespace

BayerDevelopment bayer_development(const RawColour& raw) {
  BayerDevelopment d;
  d.black_level = raw.black_level.value_or(std::array<double, 4>{0, 0, 0, 0});
  d.white_level = raw.white_level;
  d.grey_world = !raw.gains;
  if (raw.gains) d.white_balance = *raw.gains;
  d.colour_matrix = raw.colour_matrix;
  return d;
}

std::string raw_colour_problem(const RawColour& raw, PixelFormat format) {
  const double top = double((1 << bayer_bit_depth(format)) - 1);
  const double white = raw.white_level > 0 ? raw.white_level : top;
  if (!std::isfinite(raw.white_level) || raw.white_level < 0 || white > top)
    return fmt::format("the white level {} is not a code of the {}-bit format (0 means {})", raw.white_level,
                       bayer_bit_depth(format), top);
  if (raw.black_level)
    for (double black : *raw.black_level)
      if (!std::isfinite(black) || black < 0 || !(black < white))
        return fmt::format("the black level {} is not a code below the white level {}", black, white);
  if (raw.gains)
    for (double g : *raw.gains)
      if (!std::isfinite(g) || !(g > 0)) return fmt::format("the white-balance gain {} is not a positive number", g);
  if (raw.colour_matrix)
    for (double m : *raw.colour_matrix)
      if (!std::isfinite(m)) return fmt::format("the colour matrix entry {} is not a finite number", m);
  return {};
}

void normalise_bayer(const BayerMosaic& mosaic, const BayerDevelopment& development, std::vector<float>& out) {
  const double white = development.white_level > 0 ? development.white_level : double((1 << mosaic.bit_depth) - 1);
  std::array<float, 4> offset{}, scale{};
  for (int p = 0; p < 4; ++p) {
    const double black = development.black_level[size_t(p)];
    if (!(white > black) || !std::isfinite(black) || !std::isfinite(white))
      throw std::invalid_argument(fmt::format("Bayer development: the white level {} must lie above the black level {}",
                                              white, black));
    offset[size_t(p)] = float(black);
    scale[size_t(p)] = float(1.0 / (white - black));
  }
  out.resize(mosaic.values.size());
  for (int y = 0; y < mosaic.height; ++y)
    for (int x = 0; x < mosaic.width; ++x) {
      const size_t i = size_t(y) * size_t(mosaic.width) + size_t(x);
      const auto p = size_t(mosaic.cell_position_at(x, y));
      out[i] = (float(mosaic.values[i]) - offset[p]) * scale[p];
    }
}

std::array<double, 3> grey_world_gains(const std::vector<float>& normalised, int width, int height, BayerOrder order,
                                       double clip_level) {
  std::array<double, 3> sum{0, 0, 0};
  std::array<size_t, 3> count{0, 0, 0};
  for (int y = 0; y + 1 < height; y += 2)
    for (int x = 0; x + 1 < width; x += 2) {
      const float* top = normalised.data() + size_t(y) * size_t(width) + size_t(x);
      const float* bottom = top + width;
      const float cell[4] = {top[0], top[1], bottom[0], bottom[1]};
      if (std::any_of(std::begin(cell), std::end(cell), [&](float v) { return !(v < clip_level); })) continue;
      for (int i = 0; i < 4; ++i) {
        const auto c = size_t(bayer_channel_at(order, x + (i & 1), y + (i >> 1)));
        sum[c] += cell[i];
        ++count[c];
      }
    }
  if (count[0] == 0 || count[1] == 0 || count[2] == 0) return {1, 1, 1};
  const double r = sum[0] / double(count[0]), g = sum[1] / double(count[1]), b = sum[2] / double(count[2]);
  if (!(r > 0) || !(g > 0) || !(b > 0)) return {1, 1, 1};
  return {g / r, 1.0, g / b};
}

void demosaic_bayer(const std::vector<float>& normalised, int width, int height, BayerOrder order,
                    const std::array<double, 3>& gains, std::vector<float>& rgb) {
  // 16-bit code = value * gain * scale, with room for the largest gain above full scale.
  const double scale = 65535.0 / std::max(1.0, *std::max_element(gains.begin(), gains.end()));
  cv::Mat mosaic(height, width, CV_16UC1);
  for (int y = 0; y < height; ++y) {
    auto* row = mosaic.ptr<uint16_t>(y);
    const float* src = normalised.data() + size_t(y) * size_t(width);
    for (int x = 0; x < width; ++x) {
      const double v = double(src[x]) * gains[size_t(bayer_channel_at(order, x, y))] * scale;
      row[x] = uint16_t(std::lround(std::clamp(std::isnan(v) ? 0.0 : v, 0.0, 65535.0)));
    }
  }
  cv::Mat demosaiced;
  cv::demosaicing(mosaic, demosaiced, opencv_demosaic_code(order));
  rgb.resize(size_t(width) * size_t(height) * 3);
  const auto inverse = float(1.0 / scale);
  for (int y = 0; y < height; ++y) {
    const auto* row = demosaiced.ptr<uint16_t>(y);
    float* dst = rgb.data() + size_t(y) * size_t(width) * 3;
    for (int i = 0; i < width * 3; ++i) dst[i] = float(row[i]) * inverse;
  }
}

void apply_colour_matrix(const std::array<double, 9>& m, std::vector<float>& rgb) {
  std::array<float, 9> f{};
  for (size_t i = 0; i < 9; ++i) f[i] = float(m[i]);
  for (size_t p = 0; p + 2 < rgb.size(); p += 3) {
    const float r = rgb[p], g = rgb[p + 1], b = rgb[p + 2];
    rgb[p] = f[0] * r + f[1] * g + f[2] * b;
    rgb[p + 1] = f[3] * r + f[4] * g + f[5] * b;
    rgb[p + 2] = f[6] * r + f[7] * g + f[8] * b;
  }
}

void develop_bayer(const Frame& frame, const BayerDevelopment& development, std::vector<float>& linear_rgb) {
  thread_local BayerMosaic mosaic;
  thread_local std::vector<float> normalised;
  unpack_bayer(frame, mosaic);
  normalise_bayer(mosaic, development, normalised);
  const std::array<double, 3> gains = development.grey_world
                                          ? grey_world_gains(normalised, mosaic.width, mosaic.height, mosaic.order)
                                          : development.white_balance;
  for (double g : gains)
    if (!(g > 0) || !std::isfinite(g))
      throw std::invalid_argument(fmt::format("Bayer development: white balance gain {} is not a positive number", g));
  demosaic_bayer(normalised, mosaic.width, mosaic.height, mosaic.order, gains, linear_rgb);
  if (development.colour_matrix) apply_colour_matrix(*development.colour_matrix, linear_rgb);
}

void bayer_to_rgb24(const Frame& frame, const BayerDevelopment& development, std::vector<uint8_t>& out) {
  thread_local std::vector<float> linear;
  develop_bayer(frame, development, linear);
  const std::array<uint8_t, 65536>& lut = srgb_lut();
  out.resize(linear.size());
  for (size_t i = 0; i < linear.size(); ++i) {
    const float v = linear[i];
    out[i] = lut[size_t(std::lround(std::clamp(v > 0 ? v : 0.0f, 0.0f, 1.0f) * 65535.0f))];
  }
}

}  // namespace arpipe
