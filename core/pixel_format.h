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
  // Raw Bayer mosaics, named as V4L2 names them: the order is that of the top-left 2x2 cell, read
  // row by row (SRGGB: R G on row 0, G B on row 1). 8 bits: one byte a pixel; 10/12/16: the value in
  // the low bits of a little-endian 16-bit word; 10P/12P: MIPI CSI-2 packing, 4 pixels in 5 bytes
  // (four high bytes, then a byte of their 2-bit tails) or 2 pixels in 3 bytes (two high bytes, then
  // their 4-bit tails). Linear sensor values; see core/image/bayer.h for turning them into RGB.
  SRGGB8, SBGGR8, SGRBG8, SGBRG8,
  SRGGB10, SBGGR10, SGRBG10, SGBRG10,
  SRGGB12, SBGGR12, SGRBG12, SGBRG12,
  SRGGB16, SBGGR16, SGRBG16, SGBRG16,
  SRGGB10P, SBGGR10P, SGRBG10P, SGBRG10P,
  SRGGB12P, SBGGR12P, SGRBG12P, SGBRG12P,
};

// The colour filter array's top-left 2x2 cell, row by row.
enum class BayerOrder { RGGB, BGGR, GRBG, GBRG };

// "GREY", "RGB24", "YUYV", "NV12", and the Bayer formats by their V4L2 names ("SRGGB10P").
std::string_view pixel_format_name(PixelFormat format);
// Parses a name as above (case-sensitive); nullopt when unknown.
std::optional<PixelFormat> pixel_format_from_name(std::string_view name);
// V4L2 FourCC code (V4L2_PIX_FMT_*), and back.
uint32_t pixel_format_fourcc(PixelFormat format);
std::optional<PixelFormat> pixel_format_from_fourcc(uint32_t fourcc);

// Whether a format is a raw Bayer mosaic; its CFA order (nullopt when not Bayer); its bits per
// sample (8 for the 8-bit formats, 0 when not Bayer); whether it is MIPI CSI-2 packed (10P, 12P).
bool is_bayer(PixelFormat format);
std::optional<BayerOrder> bayer_order(PixelFormat format);
int bayer_bit_depth(PixelFormat format);
bool is_mipi_packed(PixelFormat format);
// "RGGB", "BGGR", "GRBG", "GBRG".
std::string_view bayer_order_name(BayerOrder order);

// Minimum bytes per line of the first plane for a given width.
size_t min_bytes_per_line(PixelFormat format, int width);
// Bytes of a whole image with the given first-plane stride (NV12's UV plane uses the same stride).
size_t image_bytes(PixelFormat format, int width, int height, size_t bytes_per_line);
// Formats with chroma subsampling and Bayer mosaics need even sizes (a 10P width a multiple of 4); returns an explanation when the size is invalid.
std::optional<std::string> check_image_size(PixelFormat format, int width, int height);

}  // namespace arpipe
