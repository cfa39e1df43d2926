// Chooses what to ask a V4L2 camera for, from what it offers and what the config asks (size, rate,
// pixel format). Pure: the device's answer to S_FMT/S_PARM is checked by the stream.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "capture/v4l2/v4l2_device.h"
#include "core/config/source_choices.h"

namespace arpipe {

struct V4L2FormatRequest {
  int width = 0;                    // 0: the first size the camera lists
  int height = 0;
  double fps = 0;                   // 0: the first rate listed for that size
  CaptureFormat pixel_format = CaptureFormat::Auto;
};

struct V4L2FormatChoice {
  uint32_t fourcc = 0;
  uint32_t width = 0;
  uint32_t height = 0;
  std::optional<V4L2Fraction> interval;  // nullopt: the camera lists none; leave its rate alone
};

// The rate a camera gives back counts as the one asked for within 0.5 % (30 fps is 1/30 or
// 333333/10000000 depending on the driver).
bool same_rate(double fps, double wanted_fps);

// FourCCs arpipe can take: its own pixel formats, those it reorders into one (v4l2_frame_layout.h),
// and MJPEG (decoded to RGB24).
bool is_usable_fourcc(uint32_t fourcc);
bool is_mjpeg_fourcc(uint32_t fourcc);  // 'MJPG' or 'JPEG'

// The first offer that satisfies the request. Auto prefers a format passed on as it is, then one
// reordered while copying, then MJPEG (decoding costs), each in the camera's order; rates match by same_rate(). Throws CameraError(Refused)
// naming `device` and listing every usable offer when nothing fits.
V4L2FormatChoice choose_v4l2_format(const std::vector<V4L2FormatOffer>& offers, const V4L2FormatRequest& request,
                                    const std::string& device);

// One line per format and size: "YUYV 640x480 @ 30, 15 fps", for messages and `arpipe cameras`.
std::string describe_v4l2_offers(const std::vector<V4L2FormatOffer>& offers);

}  // namespace arpipe
