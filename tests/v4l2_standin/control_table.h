// The camera controls of a served device (auto/manual exposure, autogain, analogue and digital
// gain) with V4L2's query/get/set rules and the changes that control events report.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <vector>

#include "core/frame.h"

namespace arpipe::standin {

// A control whose value or flags changed: what a V4L2_EVENT_CTRL reports.
struct ControlChange {
  uint32_t id = 0;
  uint32_t changes = 0;  // V4L2_EVENT_CTRL_CH_VALUE | V4L2_EVENT_CTRL_CH_FLAGS
};

class ControlTable {
 public:
  // Values start at the recorded frame's; gains map to round(gain * gain_unity).
  ControlTable(int gain_unity, const FrameMetadata& first, double max_digital_gain);

  bool exists(uint32_t id) const;
  // VIDIOC_QUERYCTRL, VIDIOC_QUERY_EXT_CTRL, VIDIOC_QUERYMENU: 0 or an errno.
  int query(v4l2_queryctrl& q) const;
  int query_ext(v4l2_query_ext_ctrl& q) const;
  int query_menu(v4l2_querymenu& m) const;

  int get(uint32_t id, int32_t& value) const;
  int get_default(uint32_t id, int32_t& value) const;
  // Checks and adjusts (integers clamp to the range, booleans to 0/1) a value as if `auto_exposure`
  // and `auto_gain` held: 0, EINVAL (unknown id, value outside the menu) or EACCES (read-only, or
  // inactive because its auto mode is on).
  int check(uint32_t id, int32_t& value, int32_t auto_exposure, int32_t auto_gain) const;
  // Sets a checked value; appends the changes (the control's value, its dependants' flags).
  void set(uint32_t id, int32_t value, std::vector<ControlChange>& changes);
  int32_t value(uint32_t id) const;

  // A frame fell due: what follows the recording takes that frame's values.
  void follow(const FrameMetadata& meta, std::vector<ControlChange>& changes);
  // The payload of a V4L2_EVENT_CTRL for the control now.
  void fill_event(uint32_t id, uint32_t changes, v4l2_event_ctrl& out) const;

 private:
  struct Control {
    uint32_t id;
    uint32_t type;
    const char* name;
    int32_t minimum, maximum, step, default_value;
    int32_t value;
    bool read_only;
  };
  const Control* find(uint32_t id) const;
  Control* find(uint32_t id);
  uint32_t flags_of(const Control& c) const;
  const Control* next_after(uint32_t id) const;
  int32_t exposure_units(int64_t exposure_ns) const;
  int32_t gain_units(double gain, const Control& c) const;

  int gain_unity_;
  std::vector<Control> controls_;  // ascending id: NEXT_CTRL enumerates in this order
};

}  // namespace arpipe::standin
