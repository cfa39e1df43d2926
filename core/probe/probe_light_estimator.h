// The per-frame light estimate from a light-probe sphere: configure once, then update() with each
// frame and its pose; smoothed over time, with a confidence, held when the probe cannot be measured.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/probe_method.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/image/camera_response.h"
#include "core/light/light_estimate.h"
#include "core/light/linear_patch.h"
#include "core/probe/probe_sphere.h"

namespace arpipe {

struct ProbeLightConfig {
  ProbeSphere sphere;
  ProbeMethod method = ProbeMethod::Auto;  // Auto: Environment for a mirror, Fit for a diffuse sphere
  int max_lights = 1;
  double smoothing_s = 0.1;       // exponential time constant on directions, irradiance and SH; 0: none
  double min_confidence = 0.2;    // below: the frame is not used (Held)
  double min_radius_px = 8;       // a probe smaller than this on screen is not analysed
  double min_rim_in_view = 0.5;   // fraction of the silhouette that must be inside the image
  double max_clipped_fraction = 0.5;  // of the probe's pixels; above: over-exposed, Held
  double light_distance_m = 0;    // known lamp distance (mirror parallax, diffuse near field); 0: unknown
  bool fit_light_distance = true;  // diffuse fit with the distance unknown: fit it (else: far light)
  double seed_tolerance = 0;      // BrightestComponentsOptions::tolerance
  CameraResponse response;        // how the camera encoded its pixels
};

// What the last update saw, for results and benchmarks.
struct ProbeDiagnostics {
  bool measured = false;
  double radius_px = 0;
  double rim_in_view = 0;
  double clipped_fraction = 0;
  double confidence = 0;
  std::vector<bool> light_clipped;  // per light: its irradiance is a lower bound
  std::vector<Vec3> raw_directions;  // per light, this frame, before smoothing
  std::vector<Vec3> raw_irradiance;
};

class ProbeLightEstimator {
 public:
  // Throws std::invalid_argument on a bad method name or values.
  void configure(const ProbeLightConfig& config);
  // One frame. Never throws: whatever goes wrong becomes a Held/None state with a note.
  LightEstimate update(const Frame& frame, const CameraModel& model, const SE3& T_cam_world, bool pose_valid) noexcept;

  const LightEstimate& last() const { return estimate_; }
  const ProbeDiagnostics& diagnostics() const { return diag_; }
  ProbeMethod method() const { return method_; }

 private:
  LightEstimate hold(std::string why);
  bool measure(const Frame& frame, const CameraModel& model, const SE3& T_cam_world, LightEstimate& fresh,
               std::string& why);
  void blend(const LightEstimate& fresh, int64_t time_ns);

  ProbeLightConfig config_;
  ProbeMethod method_ = ProbeMethod::Environment;
  LightEstimate estimate_;
  ProbeDiagnostics diag_;
  bool have_measurement_ = false;
  int64_t last_time_ns_ = 0;
  PixelRayCache rays_;
  ProbeRegion region_;
  LinearPatch patch_;
};

}  // namespace arpipe
