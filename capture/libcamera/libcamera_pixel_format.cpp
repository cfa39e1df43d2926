#include "capture/libcamera/libcamera_pixel_format.h"

#include <algorithm>

#include <libcamera/formats.h>

namespace arpipe {

namespace {

struct Pair {
  PixelFormat arpipe;
  libcamera::PixelFormat libcamera;
};

// DRM_FORMAT_BGR888 is "[23:0] B:G:R little endian": R in the first byte, as RGB24.
// DRM_FORMAT_R8 is one 8-bit channel: GREY. YUYV and NV12 have the same layout as in V4L2.
const Pair kPairs[] = {
    {PixelFormat::RGB24, libcamera::formats::BGR888},
    {PixelFormat::YUYV, libcamera::formats::YUYV},
    {PixelFormat::NV12, libcamera::formats::NV12},
    {PixelFormat::GREY, libcamera::formats::R8},
    // Raw Bayer (a raw stream role, or asked for by name), last: developed by arpipe
    // (core/image/bayer.h). libcamera's unpacked 10/12/16-bit formats hold one little-endian 16-bit
    // value a pixel as V4L2's do; its _CSI2P formats are V4L2's MIPI-packed ...P formats.
    {PixelFormat::SRGGB8, libcamera::formats::SRGGB8},
    {PixelFormat::SBGGR8, libcamera::formats::SBGGR8},
    {PixelFormat::SGRBG8, libcamera::formats::SGRBG8},
    {PixelFormat::SGBRG8, libcamera::formats::SGBRG8},
    {PixelFormat::SRGGB10, libcamera::formats::SRGGB10},
    {PixelFormat::SBGGR10, libcamera::formats::SBGGR10},
    {PixelFormat::SGRBG10, libcamera::formats::SGRBG10},
    {PixelFormat::SGBRG10, libcamera::formats::SGBRG10},
    {PixelFormat::SRGGB12, libcamera::formats::SRGGB12},
    {PixelFormat::SBGGR12, libcamera::formats::SBGGR12},
    {PixelFormat::SGRBG12, libcamera::formats::SGRBG12},
    {PixelFormat::SGBRG12, libcamera::formats::SGBRG12},
    {PixelFormat::SRGGB16, libcamera::formats::SRGGB16},
    {PixelFormat::SBGGR16, libcamera::formats::SBGGR16},
    {PixelFormat::SGRBG16, libcamera::formats::SGRBG16},
    {PixelFormat::SGBRG16, libcamera::formats::SGBRG16},
    {PixelFormat::SRGGB10P, libcamera::formats::SRGGB10_CSI2P},
    {PixelFormat::SBGGR10P, libcamera::formats::SBGGR10_CSI2P},
    {PixelFormat::SGRBG10P, libcamera::formats::SGRBG10_CSI2P},
    {PixelFormat::SGBRG10P, libcamera::formats::SGBRG10_CSI2P},
    {PixelFormat::SRGGB12P, libcamera::formats::SRGGB12_CSI2P},
    {PixelFormat::SBGGR12P, libcamera::formats::SBGGR12_CSI2P},
    {PixelFormat::SGRBG12P, libcamera::formats::SGRBG12_CSI2P},
    {PixelFormat::SGBRG12P, libcamera::formats::SGBRG12_CSI2P},
};

}  // namespace

std::optional<PixelFormat> pixel_format_from_libcamera(const libcamera::PixelFormat& format) {
  for (const auto& p : kPairs)
    if (p.libcamera == format) return p.arpipe;
  return std::nullopt;
}

libcamera::PixelFormat libcamera_pixel_format(PixelFormat format) {
  for (const auto& p : kPairs)
    if (p.arpipe == format) return p.libcamera;
  return {};
}

std::optional<PixelFormat> preferred_libcamera_format(const std::vector<libcamera::PixelFormat>& offered) {
  for (const auto& p : kPairs)  // kPairs is in the order of preference
    if (std::find(offered.begin(), offered.end(), p.libcamera) != offered.end()) return p.arpipe;
  return std::nullopt;
}

}  // namespace arpipe
