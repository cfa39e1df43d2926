#include "core/pixel_format.h"

#include <linux/videodev2.h>

namespace arpipe {

namespace {
struct FormatInfo {
  PixelFormat format;
  std::string_view name;
  uint32_t fourcc;
};
constexpr FormatInfo kFormats[] = {
    {PixelFormat::GREY, "GREY", V4L2_PIX_FMT_GREY},
    {PixelFormat::RGB24, "RGB24", V4L2_PIX_FMT_RGB24},
    {PixelFormat::YUYV, "YUYV", V4L2_PIX_FMT_YUYV},
    {PixelFormat::NV12, "NV12", V4L2_PIX_FMT_NV12},
};
}  // namespace

std::string_view pixel_format_name(PixelFormat format) {
  for (const auto& f : kFormats)
    if (f.format == format) return f.name;
  return "?";
}

std::optional<PixelFormat> pixel_format_from_name(std::string_view name) {
  for (const auto& f : kFormats)
    if (f.name == name) return f.format;
  return std::nullopt;
}

uint32_t pixel_format_fourcc(PixelFormat format) {
  for (const auto& f : kFormats)
    if (f.format == format) return f.fourcc;
  return 0;
}

std::optional<PixelFormat> pixel_format_from_fourcc(uint32_t fourcc) {
  for (const auto& f : kFormats)
    if (f.fourcc == fourcc) return f.format;
  return std::nullopt;
}

size_t min_bytes_per_line(PixelFormat format, int width) {
  switch (format) {
    case PixelFormat::GREY: return size_t(width);
    case PixelFormat::RGB24: return size_t(width) * 3;
    case PixelFormat::YUYV: return size_t(width) * 2;
    case PixelFormat::NV12: return size_t(width);
  }
  return 0;
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
  return std::nullopt;
}

}  // namespace arpipe
