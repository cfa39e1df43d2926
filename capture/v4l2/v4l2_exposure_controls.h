// The exposure and gain a V4L2 camera is using, kept current from control-change events (one
// DQEVENT per change instead of an ioctl per frame), and manual exposure and gain from the config.
#pragma once

#include <cstdint>
#include <string>

namespace arpipe {

class V4L2Device;

struct V4L2ExposureSettings {
  int64_t exposure_us = 0;  // 0: leave auto exposure on
  double gain = 0;          // 0: leave auto gain on
  double gain_unity = 100;  // the gain control's value that means gain 1
};

class V4L2ExposureControls {
 public:
  // Finds the exposure (V4L2_CID_EXPOSURE_ABSOLUTE, 100 µs units) and gain (ANALOGUE_GAIN, else
  // GAIN; DIGITAL_GAIN) controls, applies manual settings (switching auto off first), subscribes
  // to their change events and reads their values. Throws CameraError(Refused) when a manual
  // setting cannot be applied (no such control, or out of the control's range), naming the device.
  V4L2ExposureControls(const V4L2Device& device, const V4L2ExposureSettings& settings);

  // Applies every pending control event; returns how many there were. Never throws.
  int drain_events() noexcept;

  bool exposure_known() const { return exposure_id_ != 0; }
  int64_t exposure_ns() const { return exposure_100us_ * 100'000; }  // 0 when unknown
  double analogue_gain() const;
  double digital_gain() const;
  // "exposure 4.0 ms (auto), gain 1.00 (auto)" for the log.
  std::string describe() const;

 private:
  void read_current() noexcept;
  const V4L2Device& device_;
  double gain_unity_;
  uint32_t exposure_id_ = 0, gain_id_ = 0, digital_gain_id_ = 0;
  int64_t exposure_100us_ = 0, gain_value_ = 0, digital_gain_value_ = 0;
  bool manual_exposure_ = false, manual_gain_ = false;
};

}  // namespace arpipe
