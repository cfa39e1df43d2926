// Pixel formats a frame can carry, with their memory layout (planes, bytes per line).
// Names and FourCCs follow V4L2 so recordings and devices speak the same words.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace arpipe {

enum class PixelFormat {
  GREY,   // 8-bit luma
  RGB24,  // R, G, B bytes, packed
  YUYV,   // 4:2:2 packed Y0 U Y1 V (BT.601 limited range)
  NV12,   // 4:2:0: Y plane, then interleaved U V plane (BT.601 limited range)
};

// "GREY", "RGB24", "YUYV", "NV12".
std::string_view pixel_format_name(PixelFormat format);
// Parses a name as above (case-sensitive); nullopt when unknown.
std::optional<PixelFormat> pixel_format_from_name(std::string_view name);
// V4L2 FourCC code (V4L2_PIX_FMT_*), and back.
uint32_t pixel_format_fourcc(PixelFormat format);
std::optional<PixelFormat> pixel_format_from_fourcc(uint32_t fourcc);

// Minimum bytes per line of the first plane for a given width.
size_t min_bytes_per_line(PixelFormat format, int width);
// Bytes of a whole image with the given first-plane stride (NV12's UV plane uses the same stride).
size_t image_bytes(PixelFormat format, int width, int height, size_t bytes_per_line);
// Formats with chroma subsampling need even sizes; returns an explanation when the size is invalid.
std::optional<std::string> check_image_size(PixelFormat format, int width, int height);

}  // namespace arpipe
