// What `arpipe cameras` prints about one camera: identity, formats with sizes and rates, controls.
// Filled by each backend's listing (v4l2_cameras, libcamera_cameras).
#pragma once

#include <string>
#include <vector>

#include "core/config/source_choices.h"

namespace arpipe {

struct CameraMode {
  std::string format;        // "YUYV", "MJPG", "NV12", ... (the backend's own name when arpipe has none)
  int width = 0;
  int height = 0;
  std::vector<double> fps;   // discrete rates; empty when the camera does not list them
  std::string note;          // e.g. "stepwise 160x120 to 1920x1080", "fps 1 to 30"
};

struct CameraControl {
  std::string name;          // "Exposure Time, Absolute", "AnalogueGain", ...
  std::string range;         // "1..10000 step 1 default 166 (100 µs units)", ...
};

struct CameraDescription {
  SourceType backend = SourceType::V4l2;  // the source.type that opens it: V4l2 or Libcamera
  std::string id;            // what source.device / source.camera takes
  std::string name;          // card or model name
  std::string location;      // bus info, or libcamera's Location property
  std::vector<CameraMode> modes;
  std::vector<CameraControl> controls;
  std::string error;         // why it could not be listed fully (busy, permission), else empty
};

}  // namespace arpipe
