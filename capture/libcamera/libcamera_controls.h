// Between libcamera controls and arpipe: reading a request's metadata into LibcameraRequestValues,
// and building the controls the camera starts with (manual exposure and gain, frame rate).
#pragma once

#include <string>
#include <vector>

#include <libcamera/controls.h>

#include "capture/libcamera/libcamera_metadata.h"
#include "core/config/config.h"

namespace arpipe {

LibcameraRequestValues read_request_values(const libcamera::ControlList& metadata);

struct StartControls {
  libcamera::ControlList controls;
  std::vector<std::string> refused;  // what the config asks and the camera cannot do
  std::vector<std::string> notes;    // what the config asks and the camera does not offer (left out)
};

// From the config: exposure_us > 0 fixes the exposure time, gain > 0 the analogue gain (libcamera
// < 0.5: AeEnable false when both are fixed, else the fixed value alone, which the AE keeps and
// works around; >= 0.5: ExposureTimeMode / AnalogueGainMode Manual); fps > 0 sets
// FrameDurationLimits to 1/fps for both limits. Only controls that `supported` lists are set; a
// value outside its range is refused, naming the range.
StartControls build_start_controls(const SourceConfig& config, const libcamera::ControlInfoMap& supported);

}  // namespace arpipe
