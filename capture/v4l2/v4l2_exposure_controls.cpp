#include "capture/v4l2/v4l2_exposure_controls.h"

#include <linux/videodev2.h>

#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_device.h"
#include "core/log.h"

namespace arpipe {

namespace {

bool query(const V4L2Device& device, uint32_t id, v4l2_queryctrl& out) {
  out = {};
  out.id = id;
  return device.ioctl(VIDIOC_QUERYCTRL, &out) == 0 && !(out.flags & V4L2_CTRL_FLAG_DISABLED);
}

void set_control(const V4L2Device& device, uint32_t id, int64_t value, const char* what) {
  v4l2_queryctrl q{};
  if (!query(device, id, q))
    throw CameraError(CameraError::Kind::Refused, fmt::format("{}: the camera has no {} control", device.path(), what));
  if (value < q.minimum || value > q.maximum)
    throw CameraError(CameraError::Kind::Refused,
                      fmt::format("{}: {} {} is outside the camera's range {}..{}", device.path(), what, value,
                                  q.minimum, q.maximum));
  v4l2_control c{id, int32_t(value)};
  if (const int err = device.ioctl(VIDIOC_S_CTRL, &c); err != 0)
    throw CameraError(CameraError::Kind::Refused,
                      fmt::format("{}: cannot set {} to {}: {}", device.path(), what, value, std::strerror(err)));
}

// Auto modes are switched off before the value is written: drivers refuse writes to a control
// that auto mode drives (uvcvideo answers EACCES).
void set_auto_off(const V4L2Device& device, uint32_t id, int64_t off_value, const char* what) {
  v4l2_queryctrl q{};
  if (query(device, id, q)) set_control(device, id, off_value, what);
}

int64_t get_control(const V4L2Device& device, uint32_t id) {
  v4l2_control c{id, 0};
  return device.ioctl(VIDIOC_G_CTRL, &c) == 0 ? c.value : 0;
}

void subscribe(const V4L2Device& device, uint32_t id) {
  v4l2_event_subscription sub{};
  sub.type = V4L2_EVENT_CTRL;
  sub.id = id;
  if (device.ioctl(VIDIOC_SUBSCRIBE_EVENT, &sub) != 0)
    log::warn("{}: no change events for control {:#x}: exposure and gain may lag", device.path(), id);
}

}  // namespace

V4L2ExposureControls::V4L2ExposureControls(const V4L2Device& device, const V4L2ExposureSettings& settings)
    : device_(device), gain_unity_(settings.gain_unity) {
  v4l2_queryctrl q{};
  if (query(device, V4L2_CID_EXPOSURE_ABSOLUTE, q)) exposure_id_ = V4L2_CID_EXPOSURE_ABSOLUTE;
  if (query(device, V4L2_CID_ANALOGUE_GAIN, q))
    gain_id_ = V4L2_CID_ANALOGUE_GAIN;
  else if (query(device, V4L2_CID_GAIN, q))
    gain_id_ = V4L2_CID_GAIN;
  if (query(device, V4L2_CID_DIGITAL_GAIN, q)) digital_gain_id_ = V4L2_CID_DIGITAL_GAIN;

  if (settings.exposure_us > 0) {
    set_auto_off(device, V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "auto exposure");
    // 100 µs units: the nearest the control can express.
    set_control(device, V4L2_CID_EXPOSURE_ABSOLUTE, std::llround(double(settings.exposure_us) / 100.0), "exposure");
    manual_exposure_ = true;
  }
  if (settings.gain > 0) {
    set_auto_off(device, V4L2_CID_AUTOGAIN, 0, "auto gain");
    if (gain_id_ == 0)
      throw CameraError(CameraError::Kind::Refused, fmt::format("{}: the camera has no gain control", device.path()));
    set_control(device, gain_id_, std::llround(settings.gain * settings.gain_unity), "gain");
    manual_gain_ = true;
  }
  for (const uint32_t id : {exposure_id_, gain_id_, digital_gain_id_})
    if (id != 0) subscribe(device, id);
  read_current();
  drain_events();  // initial-value events, if the driver sent any
}

void V4L2ExposureControls::read_current() noexcept {
  if (exposure_id_) exposure_100us_ = get_control(device_, exposure_id_);
  if (gain_id_) gain_value_ = get_control(device_, gain_id_);
  if (digital_gain_id_) digital_gain_value_ = get_control(device_, digital_gain_id_);
}

int V4L2ExposureControls::drain_events() noexcept {
  int count = 0;
  for (;;) {
    v4l2_event event{};
    if (device_.ioctl(VIDIOC_DQEVENT, &event) != 0) break;  // ENOENT: none pending
    ++count;
    if (event.type != V4L2_EVENT_CTRL || !(event.u.ctrl.changes & V4L2_EVENT_CTRL_CH_VALUE)) continue;
    const int64_t value = event.u.ctrl.type == V4L2_CTRL_TYPE_INTEGER64 ? event.u.ctrl.value64 : event.u.ctrl.value;
    if (event.id == exposure_id_) exposure_100us_ = value;
    else if (event.id == gain_id_) gain_value_ = value;
    else if (event.id == digital_gain_id_) digital_gain_value_ = value;
  }
  return count;
}

double V4L2ExposureControls::analogue_gain() const { return gain_id_ ? double(gain_value_) / gain_unity_ : 1.0; }
double V4L2ExposureControls::digital_gain() const {
  return digital_gain_id_ ? double(digital_gain_value_) / gain_unity_ : 1.0;
}

std::string V4L2ExposureControls::describe() const {
  const std::string exposure = exposure_id_ ? fmt::format("exposure {:.1f} ms ({})", double(exposure_ns()) * 1e-6,
                                                          manual_exposure_ ? "manual" : "auto")
                                            : "exposure unknown (no V4L2_CID_EXPOSURE_ABSOLUTE)";
  const std::string gain = gain_id_ ? fmt::format("gain {:.2f} ({})", analogue_gain(), manual_gain_ ? "manual" : "auto")
                                    : "gain unknown";
  return exposure + ", " + gain;
}

}  // namespace arpipe
