// A CameraStream over a libcamera camera: one stream of the configured role, size and pixel
// format, one reused request per buffer, and per-request metadata mapped to FrameMetadata.
#pragma once

#include <memory>

#include "capture/live/camera_stream.h"
#include "core/config/config.h"

namespace arpipe {

// Finds source.camera (an id, an index into the manager's list, or "" for the first), acquires
// it, configures and starts it. Throws CameraError: Missing (no such camera; the message lists
// the ids present), Refused (the camera would adjust the size or format asked for, or cannot take
// the manual exposure, gain or rate; the message lists what it offers) or Failed.
std::unique_ptr<CameraStream> open_libcamera_stream(const SourceConfig& config);

}  // namespace arpipe
