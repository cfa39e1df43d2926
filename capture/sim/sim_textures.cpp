// The simulator's plane textures and sky.
#include "capture/sim/sim_textures.h"
#include "core/geometry/math_constants.h"
#include "core/image/srgb.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "capture/image_file.h"
#include "core/config/regular_file.h"
#include "core/image/hdr_file.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "core/track/tag_family.h"

namespace arpipe::sim {

namespace fs = std::filesystem;

namespace {

// Whole texture files are read into memory: at most 256 MiB (a 2^25-pixel 16-bit RGBA PNG stored
// uncompressed is 256 MiB).
constexpr ImageFileLimits kTextureLimits{kMaxTextureSide, kMaxTexturePixels, uint64_t{1} << 28};


int clamp_index(double x, int n) { return std::clamp(int(x), 0, n - 1); }

// The bilinear blend, weights fx across and fy down, of the texels (x0, y0), (x1, y0), (x0, y1)
// and (x1, y1) of a packed RGB image `width` texels wide.
Rgb bilinear_rgb(const std::vector<float>& rgb, int width, int x0, int x1, int y0, int y1, double fx, double fy) {
  const float* p00 = &rgb[(size_t(y0) * width + x0) * 3];
  const float* p10 = &rgb[(size_t(y0) * width + x1) * 3];
  const float* p01 = &rgb[(size_t(y1) * width + x0) * 3];
  const float* p11 = &rgb[(size_t(y1) * width + x1) * 3];
  Rgb out;
  for (int c = 0; c < 3; ++c)
    out[size_t(c)] = (1 - fy) * ((1 - fx) * p00[c] + fx * p10[c]) + fy * ((1 - fx) * p01[c] + fx * p11[c]);
  return out;
}

}  // namespace

PlaneTexture::PlaneTexture(const SimMaterial& material, const std::string& object_name)
    : kind_(material.texture.kind),
      albedo_(material.albedo),
      dark_(material.texture.dark),
      light_(material.texture.light) {
  const SimTexture& texture = material.texture;
  switch (kind_) {
    case SimTexture::Kind::None:
      break;
    case SimTexture::Kind::AprilTag: {
      const TagFamilyPtr family = create_tag_family(texture.family);
      if (!family)
        throw std::invalid_argument(fmt::format("object \"{}\": unknown tag family \"{}\" (known: {})", object_name,
                                                texture.family, joined_tag_family_names()));
      if (texture.tag_id < 0 || uint32_t(texture.tag_id) >= family->ncodes)
        throw std::invalid_argument(fmt::format("object \"{}\": tag id {} is outside {}'s 0..{}", object_name,
                                                texture.tag_id, texture.family, family->ncodes - 1));
      image_u8_t* image = apriltag_to_image(family.get(), uint32_t(texture.tag_id));
      width_ = image->width;
      height_ = image->height;
      paper_.resize(size_t(width_) * height_);
      for (int row = 0; row < height_; ++row)
        for (int col = 0; col < width_; ++col)
          paper_[size_t(row) * width_ + col] = image->buf[row * image->stride + col] >= 128 ? 1 : 0;
      image_u8_destroy(image);
      break;
    }
    case SimTexture::Kind::Chessboard:
      if (texture.rows <= 0 || texture.cols <= 0 || !(texture.margin_squares >= 0))
        throw std::invalid_argument(
            fmt::format("object \"{}\": a chessboard needs rows and cols > 0 and margin_squares >= 0, got {} x {}, "
                        "margin {}",
                        object_name, texture.rows, texture.cols, texture.margin_squares));
      board_rows_ = texture.rows;
      board_cols_ = texture.cols;
      margin_ = texture.margin_squares;
      break;
    case SimTexture::Kind::Image: {
      const std::string what = fmt::format("object \"{}\": image texture", object_name);
      const cv::Mat image = read_image_file(texture.image_path, what, kTextureLimits);
      width_ = image.cols;
      height_ = image.rows;
      std::array<float, 256> decode{};
      for (int i = 0; i < 256; ++i) decode[size_t(i)] = float(srgb_decode(i / 255.0));
      rgb_.resize(size_t(width_) * height_ * 3);
      for (int row = 0; row < height_; ++row) {
        const uint8_t* bgr = image.ptr<uint8_t>(row);
        float* out = &rgb_[size_t(row) * width_ * 3];
        for (int col = 0; col < width_; ++col)
          for (int c = 0; c < 3; ++c) out[col * 3 + c] = float(decode[bgr[col * 3 + 2 - c]] * albedo_[size_t(c)]);
      }
      break;
    }
  }
}

Rgb PlaneTexture::reflectance(double u, double v) const {
  switch (kind_) {
    case SimTexture::Kind::None:
      return albedo_;
    case SimTexture::Kind::AprilTag:
      return paper_[size_t(clamp_index(v * height_, height_)) * width_ + size_t(clamp_index(u * width_, width_))]
                 ? light_
                 : dark_;
    case SimTexture::Kind::Chessboard: {
      // Square coordinates from the board's top-left corner; the margin is paper.
      const double x = u * (board_cols_ + 2 * margin_) - margin_;
      const double y = v * (board_rows_ + 2 * margin_) - margin_;
      if (x < 0 || y < 0 || x >= board_cols_ || y >= board_rows_) return light_;
      return (int(x) + int(y)) % 2 == 0 ? dark_ : light_;
    }
    case SimTexture::Kind::Image: {
      // Bilinear between texel centres, clamped at the edges.
      const double x = std::clamp(u * width_ - 0.5, 0.0, double(width_ - 1));
      const double y = std::clamp(v * height_ - 0.5, 0.0, double(height_ - 1));
      const int x0 = std::min(int(x), width_ - 1), y0 = std::min(int(y), height_ - 1);
      const int x1 = std::min(x0 + 1, width_ - 1), y1 = std::min(y0 + 1, height_ - 1);
      return bilinear_rgb(rgb_, width_, x0, x1, y0, y1, x - x0, y - y0);
    }
  }
  return albedo_;
}

Vec2 equirect_uv(const Vec3& d, double rotation_rad) {
  double u = (std::atan2(d[1], d[0]) + rotation_rad) / (2 * kPi);
  u -= std::floor(u);
  if (u >= 1.0) u = 0.0;  // -tiny wraps to 1.0 in floating point
  return {u, std::acos(std::clamp(d[2], -1.0, 1.0)) / kPi};
}

EnvironmentMap::EnvironmentMap(const SimEnvironment& environment)
    : constant_(environment.radiance), rotation_(environment.rotation_rad) {
  if (environment.hdr_path.empty()) {
    black_ = constant_[0] == 0 && constant_[1] == 0 && constant_[2] == 0;
    return;
  }
  // The project's own HDR reader: its header limits (core/image/radiance_hdr.h) come before any
  // allocation, where OpenCV's decoder asserted on a huge declared size; it also checks every texel.
  HdrImage image;
  try {
    image = read_hdr_image(environment.hdr_path);
  } catch (const AssetError& e) {
    throw AssetError(fmt::format("HDR environment: {}", e.what()));
  }
  width_ = image.width;
  height_ = image.height;
  rgb_ = std::move(image.rgb);
  black_ = true;
  for (size_t i = 0; i < rgb_.size(); ++i) {
    rgb_[i] = float(rgb_[i] * constant_[i % 3]);
    if (rgb_[i] != 0) black_ = false;
  }
}

Rgb EnvironmentMap::radiance(const Vec3& unit_dir) const {
  if (width_ == 0) return constant_;
  const Vec2 uv = equirect_uv(unit_dir, rotation_);
  // Bilinear between texel centres: wraps around in u, clamps at the poles in v.
  const double x = uv[0] * width_ - 0.5;
  const double y = std::clamp(uv[1] * height_ - 0.5, 0.0, double(height_ - 1));
  const double xf = std::floor(x);
  const double fx = x - xf;
  int x0 = int(xf) % width_;
  if (x0 < 0) x0 += width_;
  const int x1 = x0 + 1 == width_ ? 0 : x0 + 1;
  const int y0 = std::min(int(y), height_ - 1), y1 = std::min(y0 + 1, height_ - 1);
  return bilinear_rgb(rgb_, width_, x0, x1, y0, y1, fx, y - y0);
}

}  // namespace arpipe::sim
