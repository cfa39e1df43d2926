// `arpipe cameras` for libcamera: every camera the manager sees, with the formats and sizes of a
// video configuration and its controls with their ranges. No cameras is an empty list, not an error.
#pragma once

#include <vector>

#include "capture/live/camera_description.h"

namespace libcamera {
class StreamFormats;
}

namespace arpipe {

std::vector<CameraDescription> list_libcamera_cameras();

// One mode per pixel format and discrete size (or one per format with the size range in `note`);
// the format's arpipe name when arpipe takes it, else libcamera's.
std::vector<CameraMode> libcamera_modes(const libcamera::StreamFormats& formats);

}  // namespace arpipe
