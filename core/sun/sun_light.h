// The light of an outdoor scene from place and time: the sun's direction by NREL's SPA in the
// anchor frame, its strength and the sky's from the real ground beside the anchor, per frame.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/config/config.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/image/camera_response.h"
#include "core/sun/civil_time.h"
#include "core/light/light_estimate.h"
#include "core/light/ground_radiance.h"
#include "core/sun/sun_direction.h"

namespace arpipe {

class SunLight {
 public:
  // Throws ConfigError (naming the key) on a time that does not parse or a place SPA refuses.
  void configure(const SunConfig& config, const Vec3& ground_albedo, const CameraResponse& response,
                 double smoothing_s, const std::filesystem::path& config_file);
  // realtime_minus_monotonic_ns: CLOCK_REALTIME - CLOCK_MONOTONIC now (for time = "now").
  // Never throws.
  LightEstimate update(const Frame& frame, const CameraModel& camera, const SE3& T_cam_world, bool pose_valid,
                       int64_t realtime_minus_monotonic_ns) noexcept;
  // The sun at a UTC instant (what update uses), for tests and `arpipe sun`.
  SunInWorld sun_at(const UtcInstant& time) const;
  // The UTC instant of a frame's mid-exposure.
  UtcInstant frame_time(int64_t exposure_mid_ns, int64_t realtime_minus_monotonic_ns);

 private:
  SunConfig config_;
  Vec3 ground_albedo_{0.3, 0.3, 0.3};
  GroundRadiance ground_;
  CameraResponse response_;
  double smoothing_s_ = 0.3;
  std::optional<UtcInstant> start_time_;  // time = ISO 8601: the first frame's instant
  std::optional<int64_t> first_frame_ns_;
  std::optional<Vec3> total_irradiance_;  // smoothed horizontal irradiance from the ground
  int64_t last_measured_ns_ = 0;
  int frames_since_measured_ = 0;
};

}  // namespace arpipe
