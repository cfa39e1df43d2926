// libcamera::PixelFormat <-> arpipe PixelFormat. libcamera names formats after DRM fourccs, whose
// RGB names list components from the most significant byte: formats::BGR888 is R, G, B in memory.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <libcamera/pixel_format.h>

#include "core/pixel_format.h"

namespace arpipe {

// nullopt for formats arpipe has no layout for (YUV420, RGB888 = B,G,R bytes, Bayer, ...).
std::optional<PixelFormat> pixel_format_from_libcamera(const libcamera::PixelFormat& format);
libcamera::PixelFormat libcamera_pixel_format(PixelFormat format);

// For pixel_format = "auto": the first of `offered` that arpipe takes, in the order of preference
// RGB24, YUYV, NV12, GREY (RGB24 goes to the renderer as it is); nullopt when none.
std::optional<PixelFormat> preferred_libcamera_format(const std::vector<libcamera::PixelFormat>& offered);

}  // namespace arpipe
