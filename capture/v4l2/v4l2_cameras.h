// Lists V4L2 capture devices (/dev/video*, plus paths given) with formats, sizes, rates and
// controls, for `arpipe cameras`.
#pragma once

#include <string>
#include <vector>

#include "capture/live/camera_description.h"

namespace arpipe {

// Every /dev/videoN that is a streaming video capture device (metadata and output nodes are left
// out), then each of `extra_paths` (listed even when it is not a capture device, with the reason).
// Never throws: a node that cannot be opened is listed with the error.
std::vector<CameraDescription> list_v4l2_cameras(const std::vector<std::string>& extra_paths);

// The controls of an open device, for the listing: name and range in words.
class V4L2Device;
std::vector<CameraControl> list_v4l2_controls(const V4L2Device& device);

}  // namespace arpipe
