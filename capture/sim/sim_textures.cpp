// The simulator's plane textures and sky.
#include "capture/sim/sim_textures.h"
#include "core/geometry/math_constants.h"
#include "core/image/srgb.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>
#include <png.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "core/config/regular_file.h"
#include "core/image/hdr_file.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "core/track/tag_family.h"

namespace arpipe::sim {

namespace fs = std::filesystem;

namespace {


// Decoding goes to the decoder of the format read_image_header identified, never to OpenCV's
// signature probing: that handed a JPEG with "DICM" at byte 128 to its DICOM decoder, which
// aborted the process. The output is what cv::imread(IMREAD_COLOR) gave: 8-bit BGR, the same
// libpng transforms and the same libjpeg-turbo decoding (except that EXIF orientation is not applied).

// Whole texture files are read into memory: at most 256 MiB (a 2^25-pixel 16-bit RGBA PNG stored
// uncompressed is 256 MiB).
constexpr uint64_t kMaxTextureFileBytes = uint64_t{1} << 28;

[[noreturn]] void undecodable(const fs::path& path, const std::string& what, const std::string& why) {
  throw AssetError(fmt::format("{} \"{}\": cannot be decoded: {}", what, path.string(), why));
}

void check_decoded_size(int64_t width, int64_t height, const fs::path& path, const std::string& what,
                        const std::string& format) {
  ImageHeader header{format, width, height};
  check_image_limits(header, path, what, kMaxTextureSide, kMaxTexturePixels);
}

cv::Mat decode_jpeg(const std::string& bytes, const fs::path& path, const std::string& what) {
  const std::unique_ptr<void, int (*)(tjhandle)> handle(tjInitDecompress(), tjDestroy);
  if (!handle) undecodable(path, what, "JPEG: cannot start libjpeg-turbo");
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(handle.get(), data, bytes.size(), &width, &height, &subsampling, &colorspace) != 0)
    undecodable(path, what, fmt::format("JPEG: {}", tjGetErrorStr2(handle.get())));
  check_decoded_size(width, height, path, what, "JPEG");
  cv::Mat image(height, width, CV_8UC3);
  // Flags 0: accurate integer DCT and fancy upsampling, libjpeg's defaults, as OpenCV decodes.
  // A warning (a file cut short: the rest stays grey) still yields the image, as it did in OpenCV.
  if (tjDecompress2(handle.get(), data, bytes.size(), image.data, width, static_cast<int>(image.step), height,
                    TJPF_BGR, 0) != 0 &&
      tjGetErrorCode(handle.get()) != TJERR_WARNING)
    undecodable(path, what, fmt::format("JPEG: {}", tjGetErrorStr2(handle.get())));
  return image;
}

// libpng reports errors by longjmp: the functions that call setjmp hold only trivially
// destructible locals, and the C++ objects live in decode_png.
struct PngSource {
  const std::string* bytes;
  size_t at = 0;
  char error[256] = {};
};

void png_read_from_memory(png_structp png, png_bytep out, size_t count) {
  auto* source = static_cast<PngSource*>(png_get_io_ptr(png));
  if (source->bytes->size() - source->at < count) png_error(png, "the file ends inside the image");
  std::memcpy(out, source->bytes->data() + source->at, count);
  source->at += count;
}

void png_keep_error(png_structp png, png_const_charp message) {
  auto* source = static_cast<PngSource*>(png_get_error_ptr(png));
  std::snprintf(source->error, sizeof source->error, "%s", message);
  png_longjmp(png, 1);
}

void png_ignore_warning(png_structp, png_const_charp) {}

// OpenCV's PngDecoder transforms for IMREAD_COLOR: 16 bits to their high byte, alpha dropped,
// palette and low-bit grey expanded, colour to BGR, grey to three channels.
bool png_read_header_and_set_transforms(png_structp png, png_infop info) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  const int bit_depth = png_get_bit_depth(png, info), color_type = png_get_color_type(png, info);
  if (bit_depth > 8) png_set_strip_16(png);
  png_set_strip_alpha(png);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (color_type & PNG_COLOR_MASK_COLOR)
    png_set_bgr(png);
  else
    png_set_gray_to_rgb(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  return true;
}

bool png_read_rows(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

cv::Mat decode_png(const std::string& bytes, const fs::path& path, const std::string& what) {
  PngSource source{&bytes};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, png_keep_error, png_ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const auto destroy = [&] { png_destroy_read_struct(&png, info ? &info : nullptr, nullptr); };
  if (!png || !info) {
    destroy();
    undecodable(path, what, "PNG: cannot start libpng");
  }
  png_set_read_fn(png, &source, png_read_from_memory);
  if (!png_read_header_and_set_transforms(png, info)) {
    destroy();
    undecodable(path, what, fmt::format("PNG: {}", source.error));
  }
  const auto width = png_get_image_width(png, info), height = png_get_image_height(png, info);
  const auto row_bytes = png_get_rowbytes(png, info);
  try {
    check_decoded_size(width, height, path, what, "PNG");
  } catch (...) {
    destroy();
    throw;
  }
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
  if (row_bytes != image.step) {
    destroy();
    undecodable(path, what, fmt::format("PNG: {} bytes a row after the transforms, expected {}", row_bytes, image.step));
  }
  std::vector<png_bytep> rows(height);
  for (size_t row = 0; row < rows.size(); ++row) rows[row] = image.ptr<uint8_t>(static_cast<int>(row));
  const bool read = png_read_rows(png, rows.data());
  destroy();
  if (!read) undecodable(path, what, fmt::format("PNG: {}", source.error));
  return image;
}

// The file's bytes (a regular file, at most kMaxTextureFileBytes), decoded as `header.format`.
cv::Mat read_image(const fs::path& path, const ImageHeader& header, const std::string& what) {
  std::string bytes;
  try {
    bytes = read_regular_file(path, "image texture", kMaxTextureFileBytes);
  } catch (const FileAccessError& e) {
    throw AssetError(fmt::format("{} \"{}\": {}", what, path.string(), e.action_and_reason()));
  }
  if (header.format == "PNG") return decode_png(bytes, path, what);
  if (header.format == "JPEG") return decode_jpeg(bytes, path, what);
  undecodable(path, what, fmt::format("no decoder for the format \"{}\"", header.format));
}

int clamp_index(double x, int n) { return std::clamp(int(x), 0, n - 1); }

// The size the file declares, checked before OpenCV decodes it: a few KB of PNG can declare
// 30000 x 30000 pixels (13 GB once decoded and turned into floats).
ImageHeader check_texture_header(const fs::path& path, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw AssetError(fmt::format("{} \"{}\": no such file", what, path.string()));
  ImageHeader header;
  try {
    header = read_image_header(path);
  } catch (const AssetError& e) {
    throw AssetError(fmt::format("{}: {}", what, e.what()));
  }
  check_image_limits(header, path, what, kMaxTextureSide, kMaxTexturePixels);
  return header;
}

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
      const ImageHeader header = check_texture_header(texture.image_path, what);
      const cv::Mat image = read_image(texture.image_path, header, what);
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
