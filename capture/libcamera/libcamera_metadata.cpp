#include "capture/libcamera/libcamera_metadata.h"

#include <cmath>

namespace arpipe {

LibcameraTiming libcamera_timing(int64_t timestamp_offset_ns, int64_t readout_ns, int64_t exposure_us,
                                 double gain, double fps) {
  LibcameraTiming t;
  t.timestamp_offset_ns = timestamp_offset_ns;
  t.readout_ns = readout_ns;
  t.manual_exposure_us = exposure_us > 0 ? exposure_us : 0;
  t.manual_gain = gain > 0 ? gain : 0;
  t.nominal_frame_duration_ns = fps > 0 ? static_cast<int64_t>(std::llround(1e9 / fps)) : 0;
  return t;
}

std::string libcamera_missing_names(unsigned missing) {
  static constexpr struct {
    unsigned flag;
    const char* name;
  } kNames[] = {{kMissingSensorTimestamp, "SensorTimestamp"},
                {kMissingExposure, "ExposureTime"},
                {kMissingAnalogueGain, "AnalogueGain"},
                {kMissingDigitalGain, "DigitalGain"},
                {kMissingFrameDuration, "FrameDuration"}};
  std::string out;
  for (const auto& n : kNames) {
    if (!(missing & n.flag)) continue;
    if (!out.empty()) out += ", ";
    out += n.name;
  }
  return out;
}

LibcameraMapped map_libcamera_metadata(const LibcameraRequestValues& values, uint64_t sequence,
                                       int64_t buffer_timestamp_ns, const LibcameraTiming& timing) {
  LibcameraMapped out;
  FrameMetadata& m = out.meta;
  m.sequence = sequence;

  if (values.exposure_us) {
    m.exposure_ns = *values.exposure_us * 1000;
  } else {
    out.missing |= kMissingExposure;
    m.exposure_ns = timing.manual_exposure_us * 1000;
  }
  if (values.analogue_gain) {
    m.analogue_gain = *values.analogue_gain;
  } else {
    out.missing |= kMissingAnalogueGain;
    m.analogue_gain = timing.manual_gain > 0 ? timing.manual_gain : 1.0;
  }
  if (values.digital_gain) {
    m.digital_gain = *values.digital_gain;
  } else {
    out.missing |= kMissingDigitalGain;
    m.digital_gain = 1.0;
  }
  if (values.frame_duration_us) {
    m.frame_duration_ns = *values.frame_duration_us * 1000;
  } else {
    out.missing |= kMissingFrameDuration;
    m.frame_duration_ns = timing.nominal_frame_duration_ns;
  }
  m.readout_ns = timing.readout_ns;
  m.lux = values.lux.value_or(0.0);
  m.colour_temperature_k = values.colour_temperature_k.value_or(0.0);
  if (timing.raw_bit_depth > 0) {  // a raw stream: how its values develop (core/raw_colour.h)
    if (values.sensor_black_levels_16bit) {
      const double scale = double(1 << timing.raw_bit_depth) / 65536.0;
      std::array<double, 4>& black = m.raw.black_level.emplace();
      for (size_t i = 0; i < 4; ++i) black[i] = (*values.sensor_black_levels_16bit)[i] * scale;
    }
    if (values.colour_gains_rb)
      m.raw.gains = std::array<double, 3>{(*values.colour_gains_rb)[0], 1.0, (*values.colour_gains_rb)[1]};
    m.raw.colour_matrix = values.colour_correction_matrix;
  }

  // libcamera documents SensorTimestamp as "the time when the first row of the image sensor active
  // array is exposed" (control_ids.yaml), i.e. docs/DESIGN.md's exposure start. Its clock is documented
  // as CLOCK_BOOTTIME, but pipeline handlers copy the V4L2 buffer timestamp, which is
  // CLOCK_MONOTONIC (libcamera bug 254); the two agree unless the board has been suspended.
  // Raspberry Pi's pipeline stamps the frame-start interrupt instead (first row read out, i.e.
  // exposure later, per picamera2 issue 821): docs/OPERATIONS.md says how to measure and correct it.
  if (values.sensor_timestamp_ns) {
    m.raw_timestamp_ns = *values.sensor_timestamp_ns;
    m.raw_timestamp_meaning = fixed_timestamp_meaning(timing.sensor_timestamp).value_or(TimestampMeaning::StartOfExposure);
  } else {
    out.missing |= kMissingSensorTimestamp;
    m.raw_timestamp_ns = buffer_timestamp_ns;
    m.raw_timestamp_meaning = TimestampMeaning::Sensor;
  }
  m.timestamp_offset_ns = timing.timestamp_offset_ns;
  m.exposure_start_ns = exposure_start_from_raw(m.raw_timestamp_ns, m.raw_timestamp_meaning, m.exposure_ns,
                                                m.readout_ns, m.timestamp_offset_ns);
  return out;
}

}  // namespace arpipe
