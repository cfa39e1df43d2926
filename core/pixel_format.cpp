#include "core/pixel_format.h"

#include <linux/videodev2.h>

namespace arpipe {

namespace {
struct FormatInfo {
  PixelFormat format;
  std::string_view name;
  uint32_t fourcc;
  int bayer_bits = 0;  // 0: not Bayer
  BayerOrder order = BayerOrder::RGGB;
  bool mipi_packed = false;
};
constexpr FormatInfo kFormats[] = {
    {PixelFormat::GREY, "GREY", V4L2_PIX_FMT_GREY},
    {PixelFormat::RGB24, "RGB24", V4L2_PIX_FMT_RGB24},
    {PixelFormat::YUYV, "YUYV", V4L2_PIX_FMT_YUYV},
    {PixelFormat::NV12, "NV12", V4L2_PIX_FMT_NV12},
    {PixelFormat::SRGGB8, "SRGGB8", V4L2_PIX_FMT_SRGGB8, 8, BayerOrder::RGGB},
    {PixelFormat::SBGGR8, "SBGGR8", V4L2_PIX_FMT_SBGGR8, 8, BayerOrder::BGGR},
    {PixelFormat::SGRBG8, "SGRBG8", V4L2_PIX_FMT_SGRBG8, 8, BayerOrder::GRBG},
    {PixelFormat::SGBRG8, "SGBRG8", V4L2_PIX_FMT_SGBRG8, 8, BayerOrder::GBRG},
    {PixelFormat::SRGGB10, "SRGGB10", V4L2_PIX_FMT_SRGGB10, 10, BayerOrder::RGGB},
    {PixelFormat::SBGGR10, "SBGGR10", V4L2_PIX_FMT_SBGGR10, 10, BayerOrder::BGGR},
    {PixelFormat::SGRBG10, "SGRBG10", V4L2_PIX_FMT_SGRBG10, 10, BayerOrder::GRBG},
    {PixelFormat::SGBRG10, "SGBRG10", V4L2_PIX_FMT_SGBRG10, 10, BayerOrder::GBRG},
    {PixelFormat::SRGGB12, "SRGGB12", V4L2_PIX_FMT_SRGGB12, 12, BayerOrder::RGGB},
    {PixelFormat::SBGGR12, "SBGGR12", V4L2_PIX_FMT_SBGGR12, 12, BayerOrder::BGGR},
    {PixelFormat::SGRBG12, "SGRBG12", V4L2_PIX_FMT_SGRBG12, 12, BayerOrder::GRBG},
    {PixelFormat::SGBRG12, "SGBRG12", V4L2_PIX_FMT_SGBRG12, 12, BayerOrder::GBRG},
    {PixelFormat::SRGGB16, "SRGGB16", V4L2_PIX_FMT_SRGGB16, 16, BayerOrder::RGGB},
    {PixelFormat::SBGGR16, "SBGGR16", V4L2_PIX_FMT_SBGGR16, 16, BayerOrder::BGGR},
    {PixelFormat::SGRBG16, "SGRBG16", V4L2_PIX_FMT_SGRBG16, 16, BayerOrder::GRBG},
    {PixelFormat::SGBRG16, "SGBRG16", V4L2_PIX_FMT_SGBRG16, 16, BayerOrder::GBRG},
    {PixelFormat::SRGGB10P, "SRGGB10P", V4L2_PIX_FMT_SRGGB10P, 10, BayerOrder::RGGB, true},
    {PixelFormat::SBGGR10P, "SBGGR10P", V4L2_PIX_FMT_SBGGR10P, 10, BayerOrder::BGGR, true},
    {PixelFormat::SGRBG10P, "SGRBG10P", V4L2_PIX_FMT_SGRBG10P, 10, BayerOrder::GRBG, true},
    {PixelFormat::SGBRG10P, "SGBRG10P", V4L2_PIX_FMT_SGBRG10P, 10, BayerOrder::GBRG, true},
    {PixelFormat::SRGGB12P, "SRGGB12P", V4L2_PIX_FMT_SRGGB12P, 12, BayerOrder::RGGB, true},
    {PixelFormat::SBGGR12P, "SBGGR12P", V4L2_PIX_FMT_SBGGR12P, 12, BayerOrder::BGGR, true},
    {PixelFormat::SGRBG12P, "SGRBG12P", V4L2_PIX_FMT_SGRBG12P, 12, BayerOrder::GRBG, true},
    {PixelFormat::SGBRG12P, "SGBRG12P", V4L2_PIX_FMT_SGBRG12P, 12, BayerOrder::GBRG, true},
};

const FormatInfo* info_of(PixelFormat format) {
  for (const auto& f : kFormats)
    if (f.format == format) return &f;
  return nullptr;
}
}  // namespace

std::string_view pixel_format_name(PixelFormat format) {
  const FormatInfo* f = info_of(format);
  return f ? f->name : "?";
}

std::optional<PixelFormat> pixel_format_from_name(std::string_view name) {
  for (const auto& f : kFormats)
    if (f.name == name) return f.format;
  return std::nullopt;
}

uint32_t pixel_format_fourcc(PixelFormat format) {
  const FormatInfo* f = info_of(format);
  return f ? f->fourcc : 0;
}

std::optional<PixelFormat> pixel_format_from_fourcc(uint32_t fourcc) {
  for (const auto& f : kFormats)
    if (f.fourcc == fourcc) return f.format;
  return std::nullopt;
}

bool is_bayer(PixelFormat format) { return bayer_bit_depth(format) > 0; }

std::optional<BayerOrder> bayer_order(PixelFormat format) {
  const FormatInfo* f = info_of(format);
  if (!f || f->bayer_bits == 0) return std::nullopt;
  return f->order;
}

int bayer_bit_depth(PixelFormat format) {
  const FormatInfo* f = info_of(format);
  return f ? f->bayer_bits : 0;
}

bool is_mipi_packed(PixelFormat format) {
  const FormatInfo* f = info_of(format);
  return f && f->mipi_packed;
}

std::string_view bayer_order_name(BayerOrder order) {
  switch (order) {
    case BayerOrder::RGGB: return "RGGB";
    case BayerOrder::BGGR: return "BGGR";
    case BayerOrder::GRBG: return "GRBG";
    case BayerOrder::GBRG: return "GBRG";
  }
  return "?";
}

size_t min_bytes_per_line(PixelFormat format, int width) {
  switch (format) {
    case PixelFormat::GREY: return size_t(width);
    case PixelFormat::RGB24: return size_t(width) * 3;
    case PixelFormat::YUYV: return size_t(width) * 2;
    case PixelFormat::NV12: return size_t(width);
    default: break;  // Bayer, below
  }
  const int bits = bayer_bit_depth(format);
  if (bits == 0 || width <= 0) return 0;
  // Packed: whole groups (4 pixels in 5 bytes, 2 in 3), rounded up as V4L2 drivers do.
  if (is_mipi_packed(format)) return bits == 10 ? (size_t(width) + 3) / 4 * 5 : (size_t(width) + 1) / 2 * 3;
  return bits == 8 ? size_t(width) : size_t(width) * 2;
}

size_t image_bytes(PixelFormat format, int width, int height, size_t bytes_per_line) {
  (void)width;
  if (format == PixelFormat::NV12) return bytes_per_line * size_t(height) + bytes_per_line * size_t(height / 2);
  return bytes_per_line * size_t(height);
}

std::optional<std::string> check_image_size(PixelFormat format, int width, int height) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    return "image size " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1..16384";
  if (format == PixelFormat::YUYV && width % 2 != 0) return "YUYV needs an even width";
  if (format == PixelFormat::NV12 && (width % 2 != 0 || height % 2 != 0)) return "NV12 needs an even width and height";
  if (is_bayer(format)) {
    // Whole 2x2 CFA cells; a 10P row whole 5-byte groups, so no pixel's tail bits are shared with padding.
    if (width % 2 != 0 || height % 2 != 0)
      return std::string(pixel_format_name(format)) + " (Bayer) needs an even width and height";
    if (is_mipi_packed(format) && bayer_bit_depth(format) == 10 && width % 4 != 0)
      return std::string(pixel_format_name(format)) + " (4 pixels in 5 bytes) needs a width that is a multiple of 4";
  }
  return std::nullopt;
}

}  // namespace arpipe
