// render.lens = "undistort": the camera frame warped to its lens model's pinhole core (same size),
// through a per-pixel map built once with mrcal and bilinear filtering in linear light. CPU only.
#include "render/lens/lens_undistortion.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// Linear values are looked up in steps of 1/65535, finer than half the smallest step between two
// 8-bit sRGB codes (1/255/12.92 = 3e-4), so an unmoved pixel comes back as the byte it was.
constexpr int kEncodeSteps = 65535;

double decode_srgb(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}
double encode_srgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

const std::array<float, 256>& decode_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (size_t i = 0; i < t.size(); ++i) t[i] = static_cast<float>(decode_srgb(double(i) / 255));
    return t;
  }();
  return table;
}

const std::vector<uint8_t>& encode_table() {
  static const std::vector<uint8_t> table = [] {
    std::vector<uint8_t> t(kEncodeSteps + 1);
    for (size_t i = 0; i < t.size(); ++i)
      t[i] = static_cast<uint8_t>(std::lround(255 * encode_srgb(double(i) / kEncodeSteps)));
    return t;
  }();
  return table;
}

}  // namespace

void check_lens_undistortable(const CameraModel& model) {
  if (!model.has_core())
    throw RenderError(fmt::format("lens model {} has no pinhole core (fx, fy, cx, cy) to undistort the camera "
                                  "frame to, so render.lens = \"undistort\" cannot use it",
                                  model.lensmodel()));
}

LensUndistortion::LensUndistortion(const CameraModel& model)
    : width_(model.width()), height_(model.height()), identity_(model.is_pinhole()) {
  check_lens_undistortable(model);
  if (width_ > 32767 || height_ > 32767)
    throw RenderError(fmt::format("a {}x{} image is too large to undistort", width_, height_));
  pinhole_core_ = std::make_shared<const CameraModel>(
      CameraModel::pinhole(model.fx(), model.fy(), model.cx(), model.cy(), width_, height_));
  if (identity_) return;

  std::vector<Vec3> rays;
  rays.reserve(size_t(width_) * height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) rays.push_back({(x - model.cx()) / model.fx(), (y - model.cy()) / model.fy(), 1.0});
  std::vector<Vec2> sources;
  model.project(rays, sources);
  taps_.resize(sources.size());
  for (size_t i = 0; i < sources.size(); ++i) {
    const double sx = sources[i][0], sy = sources[i][1];
    // Pixel k covers [k - 0.5, k + 0.5] (mrcal's centres are integers); inside the image's
    // outer half pixel the border pixel is repeated.
    if (!(sx >= -0.5 && sx <= width_ - 0.5 && sy >= -0.5 && sy <= height_ - 0.5)) continue;
    const double fx0 = std::floor(sx), fy0 = std::floor(sy);
    Tap& tap = taps_[i];
    tap.x0 = static_cast<int16_t>(std::clamp(fx0, 0.0, width_ - 1.0));
    tap.y0 = static_cast<int16_t>(std::clamp(fy0, 0.0, height_ - 1.0));
    tap.dx = fx0 >= 0 && fx0 + 1 <= width_ - 1 ? 1 : 0;
    tap.dy = fy0 >= 0 && fy0 + 1 <= height_ - 1 ? 1 : 0;
    tap.fx = static_cast<float>(sx - fx0);
    tap.fy = static_cast<float>(sy - fy0);
  }
}

void LensUndistortion::apply(const Frame& source, Frame& out) const {
  if (source.format != PixelFormat::RGB24 || source.width != width_ || source.height != height_)
    throw std::invalid_argument(fmt::format("LensUndistortion::apply: expected an RGB24 {}x{} frame, got {}x{}",
                                            width_, height_, source.width, source.height));
  if (out.format != PixelFormat::RGB24 || out.width != width_ || out.height != height_ || out.empty()) {
    const FrameMetadata meta = out.meta;
    out = Frame::allocate(PixelFormat::RGB24, width_, height_);
    out.meta = meta;
  }
  if (identity_) {
    for (int y = 0; y < height_; ++y)
      std::copy_n(source.data.data() + size_t(y) * source.bytes_per_line, size_t(width_) * 3,
                  out.data.data() + size_t(y) * out.bytes_per_line);
    return;
  }
  const std::array<float, 256>& decode = decode_table();
  const std::vector<uint8_t>& encode = encode_table();
  const size_t stride = source.bytes_per_line;
  for (int y = 0; y < height_; ++y) {
    uint8_t* to = out.data.data() + size_t(y) * out.bytes_per_line;
    const Tap* tap = taps_.data() + size_t(y) * width_;
    for (int x = 0; x < width_; ++x, ++tap, to += 3) {
      if (tap->x0 < 0) {
        to[0] = to[1] = to[2] = 0;
        continue;
      }
      const uint8_t* p00 = source.data.data() + size_t(tap->y0) * stride + size_t(tap->x0) * 3;
      const uint8_t* p10 = p00 + 3 * tap->dx;
      const uint8_t* p01 = p00 + stride * tap->dy;
      const uint8_t* p11 = p01 + 3 * tap->dx;
      const float wx = tap->fx, wy = tap->fy;
      for (size_t c = 0; c < 3; ++c) {
        const float top = decode[p00[c]] + wx * (decode[p10[c]] - decode[p00[c]]);
        const float bottom = decode[p01[c]] + wx * (decode[p11[c]] - decode[p01[c]]);
        const float linear = std::clamp(top + wy * (bottom - top), 0.0f, 1.0f);
        to[c] = encode[size_t(linear * kEncodeSteps + 0.5f)];
      }
    }
  }
}

}  // namespace arpipe
