// A streaming V4L2 capture device as a CameraStream: negotiates format and rate, maps buffers,
// waits in poll(), dequeues, converts (MJPEG -> RGB24) and requeues; exposure from control events.
#pragma once

#include <memory>
#include <string>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_exposure_controls.h"
#include "capture/v4l2/v4l2_negotiation.h"
#include "core/config/config.h"

namespace arpipe {

struct V4L2StreamSettings {
  std::string device;                       // /dev/videoN or a by-id / by-path link
  V4L2FormatRequest request;
  uint32_t buffers = 4;
  V4L2ExposureSettings exposure;
  BufferTimestamps timestamp_meaning = BufferTimestamps::DriverFlag;
  int64_t readout_ns = 0;
  int64_t timestamp_offset_ns = 0;
};

V4L2StreamSettings v4l2_stream_settings(const SourceConfig& config);

// Opens, negotiates and starts streaming. Throws CameraError: Missing (no such node now),
// Refused (the camera cannot do what was asked: the message lists what it offers), Failed.
std::unique_ptr<CameraStream> open_v4l2_stream(const V4L2StreamSettings& settings);

}  // namespace arpipe
