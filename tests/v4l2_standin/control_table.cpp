#include "control_table.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace arpipe::standin {

namespace {
constexpr int64_t kExposureUnitNs = 100000;  // V4L2_CID_EXPOSURE_ABSOLUTE counts 100 µs
bool menu_has(int32_t value) { return value == V4L2_EXPOSURE_MANUAL || value == V4L2_EXPOSURE_APERTURE_PRIORITY; }
const char* menu_name(int32_t value) {
  return value == V4L2_EXPOSURE_MANUAL ? "Manual Mode" : "Aperture Priority Mode";  // uvcvideo's names
}
}  // namespace

ControlTable::ControlTable(int gain_unity, const FrameMetadata& first, double max_digital_gain) : gain_unity_(gain_unity) {
  const int32_t g16 = 16 * gain_unity;
  const int32_t dmax = std::max<int32_t>(g16, int32_t(std::lround(max_digital_gain * gain_unity)));
  controls_ = {
      {V4L2_CID_AUTOGAIN, V4L2_CTRL_TYPE_BOOLEAN, "Gain, Automatic", 0, 1, 1, 1, 1, false},
      {V4L2_CID_EXPOSURE_AUTO, V4L2_CTRL_TYPE_MENU, "Auto Exposure", V4L2_EXPOSURE_MANUAL, V4L2_EXPOSURE_APERTURE_PRIORITY, 1,
       V4L2_EXPOSURE_APERTURE_PRIORITY, V4L2_EXPOSURE_APERTURE_PRIORITY, false},
      {V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CTRL_TYPE_INTEGER, "Exposure Time, Absolute", 1, 10000, 1, 0, 0, false},
      {V4L2_CID_ANALOGUE_GAIN, V4L2_CTRL_TYPE_INTEGER, "Analogue Gain", gain_unity, g16, 1, 0, 0, false},
      {V4L2_CID_DIGITAL_GAIN, V4L2_CTRL_TYPE_INTEGER, "Digital Gain", 0, dmax, 1, 0, 0, true},
  };
  std::sort(controls_.begin(), controls_.end(), [](const Control& a, const Control& b) { return a.id < b.id; });
  Control& exposure = *find(V4L2_CID_EXPOSURE_ABSOLUTE);
  exposure.value = exposure.default_value = exposure_units(first.exposure_ns);
  Control& analogue = *find(V4L2_CID_ANALOGUE_GAIN);
  analogue.value = analogue.default_value = gain_units(first.analogue_gain, analogue);
  Control& digital = *find(V4L2_CID_DIGITAL_GAIN);
  digital.value = digital.default_value = gain_units(first.digital_gain, digital);
}

const ControlTable::Control* ControlTable::find(uint32_t id) const {
  for (const Control& c : controls_)
    if (c.id == id) return &c;
  return nullptr;
}
ControlTable::Control* ControlTable::find(uint32_t id) {
  return const_cast<Control*>(static_cast<const ControlTable*>(this)->find(id));
}
bool ControlTable::exists(uint32_t id) const { return find(id) != nullptr; }

int32_t ControlTable::value(uint32_t id) const { return find(id)->value; }

int32_t ControlTable::exposure_units(int64_t exposure_ns) const {
  const int64_t units = (exposure_ns + kExposureUnitNs / 2) / kExposureUnitNs;
  return int32_t(std::clamp<int64_t>(units, 1, 10000));
}
int32_t ControlTable::gain_units(double gain, const Control& c) const {
  return std::clamp(int32_t(std::lround(gain * gain_unity_)), c.minimum, c.maximum);
}

uint32_t ControlTable::flags_of(const Control& c) const {
  uint32_t flags = c.read_only ? V4L2_CTRL_FLAG_READ_ONLY : 0;
  if (c.id == V4L2_CID_EXPOSURE_ABSOLUTE && value(V4L2_CID_EXPOSURE_AUTO) != V4L2_EXPOSURE_MANUAL)
    flags |= V4L2_CTRL_FLAG_INACTIVE;
  if (c.id == V4L2_CID_ANALOGUE_GAIN && value(V4L2_CID_AUTOGAIN) != 0) flags |= V4L2_CTRL_FLAG_INACTIVE;
  return flags;
}

const ControlTable::Control* ControlTable::next_after(uint32_t id) const {
  for (const Control& c : controls_)
    if (c.id > id) return &c;
  return nullptr;
}

int ControlTable::query_ext(v4l2_query_ext_ctrl& q) const {
  const uint32_t next_flags = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  const uint32_t id = q.id & ~next_flags;
  const Control* c = nullptr;
  if ((q.id & next_flags) == 0) {
    c = find(id);
  } else if (q.id & V4L2_CTRL_FLAG_NEXT_CTRL) {  // no compound controls: NEXT_COMPOUND alone finds none
    c = next_after(id);
  }
  if (c == nullptr) return EINVAL;
  std::memset(&q, 0, sizeof q);
  q.id = c->id;
  q.type = c->type;
  std::strncpy(q.name, c->name, sizeof q.name - 1);
  q.minimum = c->minimum;
  q.maximum = c->maximum;
  q.step = uint64_t(c->step);
  q.default_value = c->default_value;
  q.flags = flags_of(*c);
  q.elem_size = sizeof(int32_t);
  q.elems = 1;
  q.nr_of_dims = 0;
  return 0;
}

int ControlTable::query(v4l2_queryctrl& q) const {
  v4l2_query_ext_ctrl ext{};
  ext.id = q.id;
  // QUERYCTRL knows NEXT_CTRL only; with NEXT_COMPOUND set too it still must find plain controls.
  if (q.id & V4L2_CTRL_FLAG_NEXT_COMPOUND) ext.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  if (const int err = query_ext(ext)) return err;
  std::memset(&q, 0, sizeof q);
  q.id = ext.id;
  q.type = ext.type;
  std::memcpy(q.name, ext.name, sizeof q.name - 1);
  q.minimum = int32_t(ext.minimum);
  q.maximum = int32_t(ext.maximum);
  q.step = int32_t(ext.step);
  q.default_value = int32_t(ext.default_value);
  q.flags = ext.flags;
  return 0;
}

int ControlTable::query_menu(v4l2_querymenu& m) const {
  const Control* c = find(m.id);
  if (c == nullptr || c->type != V4L2_CTRL_TYPE_MENU) return EINVAL;
  const int32_t index = int32_t(m.index);
  if (index < c->minimum || index > c->maximum || !menu_has(index)) return EINVAL;
  const uint32_t id = m.id, idx = m.index;
  std::memset(&m, 0, sizeof m);
  m.id = id;
  m.index = idx;
  std::strncpy(reinterpret_cast<char*>(m.name), menu_name(index), sizeof m.name - 1);
  return 0;
}

int ControlTable::get(uint32_t id, int32_t& value) const {
  const Control* c = find(id);
  if (c == nullptr) return EINVAL;
  value = c->value;
  return 0;
}

int ControlTable::get_default(uint32_t id, int32_t& value) const {
  const Control* c = find(id);
  if (c == nullptr) return EINVAL;
  value = c->default_value;
  return 0;
}

int ControlTable::check(uint32_t id, int32_t& value, int32_t auto_exposure, int32_t auto_gain) const {
  const Control* c = find(id);
  if (c == nullptr) return EINVAL;
  if (c->read_only) return EACCES;
  if (id == V4L2_CID_EXPOSURE_ABSOLUTE && auto_exposure != V4L2_EXPOSURE_MANUAL) return EACCES;
  if (id == V4L2_CID_ANALOGUE_GAIN && auto_gain != 0) return EACCES;
  switch (c->type) {
    case V4L2_CTRL_TYPE_MENU:
      if (value < c->minimum || value > c->maximum || !menu_has(value)) return EINVAL;
      break;
    case V4L2_CTRL_TYPE_BOOLEAN: value = value != 0; break;
    default: value = std::clamp(value, c->minimum, c->maximum); break;  // as uvcvideo and v4l2-ctrls do
  }
  return 0;
}

void ControlTable::set(uint32_t id, int32_t value, std::vector<ControlChange>& changes) {
  Control& c = *find(id);
  if (c.value == value) return;
  c.value = value;
  changes.push_back({id, V4L2_EVENT_CTRL_CH_VALUE});
  // The auto controls switch their manual partner between active and inactive.
  if (id == V4L2_CID_EXPOSURE_AUTO) changes.push_back({V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_EVENT_CTRL_CH_FLAGS});
  if (id == V4L2_CID_AUTOGAIN) changes.push_back({V4L2_CID_ANALOGUE_GAIN, V4L2_EVENT_CTRL_CH_FLAGS});
}

void ControlTable::follow(const FrameMetadata& meta, std::vector<ControlChange>& changes) {
  const auto update = [&](uint32_t id, int32_t v) {
    Control& c = *find(id);
    if (c.value == v) return;
    c.value = v;
    changes.push_back({id, V4L2_EVENT_CTRL_CH_VALUE});
  };
  if (value(V4L2_CID_EXPOSURE_AUTO) != V4L2_EXPOSURE_MANUAL) update(V4L2_CID_EXPOSURE_ABSOLUTE, exposure_units(meta.exposure_ns));
  if (value(V4L2_CID_AUTOGAIN) != 0) update(V4L2_CID_ANALOGUE_GAIN, gain_units(meta.analogue_gain, *find(V4L2_CID_ANALOGUE_GAIN)));
  update(V4L2_CID_DIGITAL_GAIN, gain_units(meta.digital_gain, *find(V4L2_CID_DIGITAL_GAIN)));
}

void ControlTable::fill_event(uint32_t id, uint32_t changes, v4l2_event_ctrl& out) const {
  const Control& c = *find(id);
  std::memset(&out, 0, sizeof out);
  out.changes = changes;
  out.type = c.type;
  out.value = c.value;
  out.flags = flags_of(c);
  out.minimum = c.minimum;
  out.maximum = c.maximum;
  out.step = c.step;
  out.default_value = c.default_value;
}

}  // namespace arpipe::standin
