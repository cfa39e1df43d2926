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
