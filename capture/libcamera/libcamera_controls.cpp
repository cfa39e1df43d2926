#include "capture/libcamera/libcamera_controls.h"

#include <array>
#include <cmath>
#include <optional>

#include <fmt/format.h>
#include <libcamera/control_ids.h>
#include <libcamera/version.h>

namespace arpipe {

namespace {

// A scalar numeric ControlValue as a double; nullopt for arrays, strings, rectangles, none.
std::optional<double> as_number(const libcamera::ControlValue& v) {
  if (v.isArray()) return std::nullopt;
  switch (v.type()) {
    case libcamera::ControlTypeByte: return v.get<uint8_t>();
    case libcamera::ControlTypeInteger32: return v.get<int32_t>();
    case libcamera::ControlTypeInteger64: return static_cast<double>(v.get<int64_t>());
    case libcamera::ControlTypeFloat: return v.get<float>();
    default: return std::nullopt;
  }
}

const libcamera::ControlInfo* find_info(const libcamera::ControlInfoMap& supported, const libcamera::ControlId& id) {
  auto it = supported.find(&id);
  return it == supported.end() ? nullptr : &it->second;
}

// Empty when `value` lies in the control's range (or the range is not numeric), else why not.
std::string out_of_range(const libcamera::ControlInfo& info, const libcamera::ControlId& id, double value,
                         const char* unit) {
  auto lo = as_number(info.min());
  auto hi = as_number(info.max());
  // Pipelines leave max 0 (or below min) when there is no upper limit yet (camera_ros issue 33).
  bool has_hi = hi && (!lo || *hi > *lo);
  if ((lo && value < *lo) || (has_hi && value > *hi))
    return fmt::format("{} {}{} is outside the camera's range {}", id.name(), value, unit, info.toString());
  return {};
}

}  // namespace

LibcameraRequestValues read_request_values(const libcamera::ControlList& metadata) {
  namespace c = libcamera::controls;
  LibcameraRequestValues v;
  if (auto x = metadata.get(c::SensorTimestamp)) v.sensor_timestamp_ns = static_cast<int64_t>(*x);
  if (auto x = metadata.get(c::ExposureTime)) v.exposure_us = static_cast<int64_t>(*x);
  if (auto x = metadata.get(c::AnalogueGain)) v.analogue_gain = static_cast<double>(*x);
  if (auto x = metadata.get(c::DigitalGain)) v.digital_gain = static_cast<double>(*x);
  if (auto x = metadata.get(c::FrameDuration)) v.frame_duration_us = static_cast<int64_t>(*x);
  if (auto x = metadata.get(c::Lux)) v.lux = static_cast<double>(*x);
  if (auto x = metadata.get(c::ColourTemperature)) v.colour_temperature_k = static_cast<double>(*x);
  if (auto x = metadata.get(c::SensorBlackLevels); x && x->size() == 4)
    v.sensor_black_levels_16bit = std::array<double, 4>{double((*x)[0]), double((*x)[1]), double((*x)[2]), double((*x)[3])};
  if (auto x = metadata.get(c::ColourGains); x && x->size() == 2)
    v.colour_gains_rb = std::array<double, 2>{double((*x)[0]), double((*x)[1])};
  if (auto x = metadata.get(c::ColourCorrectionMatrix); x && x->size() == 9) {
    std::array<double, 9>& m = v.colour_correction_matrix.emplace();
    for (size_t i = 0; i < 9; ++i) m[i] = double((*x)[i]);
  }
  return v;
}

StartControls build_start_controls(const SourceConfig& config, const libcamera::ControlInfoMap& supported) {
  namespace c = libcamera::controls;
  StartControls out{libcamera::ControlList(c::controls), {}, {}};
  const bool manual_exposure = config.exposure_us > 0;
  const bool manual_gain = config.gain > 0;

  if (manual_exposure) {
    if (const auto* info = find_info(supported, c::ExposureTime)) {
      auto why = out_of_range(*info, c::ExposureTime, static_cast<double>(config.exposure_us), " µs");
      if (why.empty())
        out.controls.set(c::ExposureTime, static_cast<decltype(c::ExposureTime)::type>(config.exposure_us));
      else
        out.refused.push_back(why);
    } else {
      out.refused.push_back(fmt::format("manual exposure ({} µs): the camera has no ExposureTime control",
                                        config.exposure_us));
    }
  }
  if (manual_gain) {
    if (const auto* info = find_info(supported, c::AnalogueGain)) {
      auto why = out_of_range(*info, c::AnalogueGain, config.gain, "");
      if (why.empty())
        out.controls.set(c::AnalogueGain, static_cast<decltype(c::AnalogueGain)::type>(config.gain));
      else
        out.refused.push_back(why);
    } else {
      out.refused.push_back(fmt::format("manual gain ({}): the camera has no AnalogueGain control", config.gain));
    }
  }
  // ExposureTimeMode / AnalogueGainMode arrived in libcamera 0.5 and took over from AeEnable.
#if LIBCAMERA_VERSION_MAJOR > 0 || LIBCAMERA_VERSION_MINOR >= 5
  if (manual_exposure && find_info(supported, c::ExposureTimeMode))
    out.controls.set(c::ExposureTimeMode, c::ExposureTimeModeManual);
  if (manual_gain && find_info(supported, c::AnalogueGainMode))
    out.controls.set(c::AnalogueGainMode, c::AnalogueGainModeManual);
#else
  // With one of the two left to the AE, AeEnable stays on: a fixed ExposureTime or AnalogueGain
  // is kept by the AE, which adjusts the other ("Setting this value means that it is now fixed").
  if (manual_exposure && manual_gain && find_info(supported, c::AeEnable)) out.controls.set(c::AeEnable, false);
#endif

  if (config.fps > 0) {
    const int64_t duration_us = std::llround(1e6 / config.fps);
    if (const auto* info = find_info(supported, c::FrameDurationLimits)) {
      auto why = out_of_range(*info, c::FrameDurationLimits, static_cast<double>(duration_us), " µs");
      if (why.empty()) {
        const std::array<int64_t, 2> limits{duration_us, duration_us};
        out.controls.set(c::FrameDurationLimits, libcamera::Span<const int64_t, 2>(limits));
      } else {
        out.refused.push_back(fmt::format("{} fps: {}", config.fps, why));
      }
    } else {
      out.notes.push_back(fmt::format(
          "{} fps: the camera has no FrameDurationLimits control; it runs at the rate its mode gives", config.fps));
    }
  }
  return out;
}

}  // namespace arpipe
