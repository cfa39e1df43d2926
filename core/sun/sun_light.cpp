// The sun's light from place and time (see sun_light.h).
#include "core/sun/sun_light.h"
#include "core/geometry/math_constants.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/sh/sh_basis.h"
#include "core/sun/delta_t.h"
#include "core/sun/sun_position_spa.h"

namespace arpipe {
namespace {


// SH (Green's order) of radiance `up` over the upper hemisphere and `down` below: only the
// constant and the z term survive (the l = 2, m = 0 term integrates to zero over a hemisphere).
// Over the upper hemisphere Y_00 = y0 integrates to 2 pi y0 and Y_10 = y1 z to pi y1, with y0 and
// y1 the basis at the pole.
ShRgb9 hemispheres_sh(const Vec3& up, const Vec3& down) {
  std::array<double, 4> pole;
  sh_basis(2, {0, 0, 1}, pole);
  const double y0 = pole[size_t(sh_index(0, 0))], y1 = pole[size_t(sh_index(1, 0))];
  ShRgb9 sh{};
  sh[size_t(sh_index(0, 0))] = (y0 * 2 * kPi) * (up + down);
  sh[size_t(sh_index(1, 0))] = (y1 * kPi) * (up - down);
  return sh;
}

}  // namespace

void SunLight::configure(const SunConfig& config, const Vec3& ground_albedo, const CameraResponse& response,
                         double smoothing_s, const std::filesystem::path& config_file) {
  config_ = config;
  ground_albedo_ = ground_albedo;
  response_ = response;
  smoothing_s_ = smoothing_s;
  start_time_.reset();
  first_frame_ns_.reset();
  total_irradiance_.reset();
  frames_since_measured_ = 0;
  if (config.time != "now") {
    try {
      start_time_ = UtcInstant::parse(config.time);
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: light.sun.time: {} (expected \"now\" or an ISO 8601 instant such as "
                                    "\"2026-06-21T10:30:00Z\")",
                                    config_file.string(), e.what()));
    }
  }
  // SPA's own checks on the place (the config has checked the ranges; this catches the rest).
  try {
    SpaInput in;
    in.time = start_time_ ? *start_time_ : UtcInstant::from_unix_seconds(1'767'225'600);  // 2026-01-01
    in.latitude_deg = config.latitude_deg;
    in.longitude_deg = config.longitude_deg;
    in.elevation_m = config.altitude_m;
    in.pressure_mbar = config.pressure_mbar;
    in.temperature_c = config.temperature_c;
    validate_spa_input(in);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: [light.sun]: {}", config_file.string(), e.what()));
  }
}

UtcInstant SunLight::frame_time(int64_t exposure_mid_ns, int64_t realtime_minus_monotonic_ns) {
  if (!start_time_) return UtcInstant::from_unix_ns(exposure_mid_ns + realtime_minus_monotonic_ns);
  if (!first_frame_ns_) first_frame_ns_ = exposure_mid_ns;
  return start_time_->plus_seconds(1e-9 * double(exposure_mid_ns - *first_frame_ns_));
}

SunInWorld SunLight::sun_at(const UtcInstant& time) const {
  SpaInput in;
  in.time = time;
  in.delta_t_s = delta_t_estimate_s(time.decimal_year());
  in.latitude_deg = config_.latitude_deg;
  in.longitude_deg = config_.longitude_deg;
  in.elevation_m = config_.altitude_m;
  in.pressure_mbar = config_.pressure_mbar;
  in.temperature_c = config_.temperature_c;
  const SpaResult sun = spa_sun_position(in);
  return sun_in_world(sun.zenith, sun.zenith_geometric, sun.azimuth, {config_.heading_deg, config_.declination_deg});
}

LightEstimate SunLight::update(const Frame& frame, const CameraModel& camera, const SE3& T_cam_world, bool pose_valid,
                               int64_t realtime_minus_monotonic_ns) noexcept {
  LightEstimate out;
  out.source = "sun";
  out.scene_linear = true;
  try {
    const int64_t mid_ns = frame.meta.exposure_mid_ns();
    const SunInWorld sun = sun_at(frame_time(mid_ns, realtime_minus_monotonic_ns));
    // The overall level: the real ground's radiance is albedo / pi times the light on it.
    std::string why;
    std::optional<Vec3> radiance = pose_valid ? ground_.measure(frame, camera, T_cam_world, response_) : std::nullopt;
    if (!pose_valid) why = "no pose: the ground could not be found";
    else if (!radiance) why = "too little of the ground around the anchor is in view or unclipped";
    if (radiance) {
      Vec3 total{};
      for (size_t c = 0; c < 3; ++c) total[c] = kPi * (*radiance)[c] / ground_albedo_[c];
      const double dt = total_irradiance_ ? 1e-9 * double(mid_ns - last_measured_ns_) : 0;
      const double keep = total_irradiance_ && smoothing_s_ > 0 ? std::exp(-std::max(dt, 0.0) / smoothing_s_) : 0;
      total_irradiance_ = total_irradiance_ ? keep * *total_irradiance_ + (1 - keep) * total : total;
      last_measured_ns_ = mid_ns;
      frames_since_measured_ = 0;
    } else {
      ++frames_since_measured_;
    }
    if (!total_irradiance_) {
      out.state = LightState::None;
      out.note = why;
      return out;
    }
    const Vec3 total = *total_irradiance_;
    const double sin_elevation = std::sin(sun.elevation_deg * kPi / 180);
    const bool direct = sun.above_horizon && sin_elevation > 0.02;
    // Sun and sky share the ground's light as configured; below the horizon all of it is sky.
    const double fraction = direct ? config_.direct_fraction : 0.0;
    const Vec3 sky_irradiance = (1 - fraction) * total;
    out.ambient_sh = hemispheres_sh((1 / kPi) * sky_irradiance,
                                    (1 / kPi) * Vec3{ground_albedo_[0] * total[0], ground_albedo_[1] * total[1],
                                                     ground_albedo_[2] * total[2]});
    if (direct) {
      DirectionalLight light;
      light.direction_world = sun.towards_sun_world;
      light.irradiance = (fraction / sin_elevation) * total;
      light.angular_diameter_rad = 2 * kSunAngularRadiusDeg * kPi / 180;
      out.lights.push_back(light);
    }
    out.state = !direct ? LightState::NoDirect : (radiance ? LightState::Estimated : LightState::Held);
    out.frames_since_measured = frames_since_measured_;
    out.confidence = radiance ? 1.0 : std::exp(-frames_since_measured_ / 30.0);
    out.note = !direct ? fmt::format("the sun is below the horizon (elevation {:.2f} deg): no direct light",
                                     sun.elevation_deg)
                       : why;
  } catch (const std::exception& e) {
    out.state = LightState::None;
    out.note = fmt::format("sun: {}", e.what());
  }
  return out;
}

}  // namespace arpipe
