#include "core/probe/probe_light_estimator.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <stdexcept>

#include <fmt/format.h>

#include "core/probe/diffuse_probe.h"
#include "core/probe/mirror_probe.h"
#include "core/probe/brightest_components.h"

namespace arpipe {

void ProbeLightEstimator::configure(const ProbeLightConfig& config) {
  const bool mirror = config.sphere.kind == ProbeSphere::Kind::Mirror;
  const ProbeMethod method = config.method == ProbeMethod::Auto ? (mirror ? ProbeMethod::Environment : ProbeMethod::Fit)
                                                                : config.method;
  if (method == ProbeMethod::Environment && !mirror)
    throw std::invalid_argument("light.probe.method \"environment\" needs a mirror probe");
  if (method == ProbeMethod::Fit && mirror)
    throw std::invalid_argument("light.probe.method \"fit\" needs a diffuse probe");
  if (!(config.sphere.radius_m > 0)) throw std::invalid_argument("light.probe.radius must be > 0");
  if (!(config.sphere.reflectance > 0 && config.sphere.reflectance <= 1))
    throw std::invalid_argument("light.probe.reflectance must be in (0, 1]");
  if (config.max_lights < 1) throw std::invalid_argument("light.probe.max_lights must be >= 1");
  if (!(config.smoothing_s >= 0)) throw std::invalid_argument("light.probe.smoothing must be >= 0");
  config_ = config;
  method_ = method;
  estimate_ = LightEstimate{};
  estimate_.state = LightState::None;
  estimate_.source = mirror ? "mirror-probe" : "diffuse-probe";
  estimate_.scene_linear = true;
  estimate_.note = "no probe measurement yet";
  have_measurement_ = false;
  diag_ = {};
}

LightEstimate ProbeLightEstimator::hold(std::string why) {
  if (have_measurement_) {
    estimate_.state = LightState::Held;
    ++estimate_.frames_since_measured;
  } else {
    estimate_.state = LightState::None;
  }
  estimate_.note = std::move(why);
  return estimate_;
}

bool ProbeLightEstimator::measure(const Frame& frame, const CameraModel& model, const SE3& T_cam_world,
                                  LightEstimate& fresh, std::string& why) {
  const ProbeSphere& sphere = config_.sphere;
  if (!compute_probe_region(sphere, model, T_cam_world, rays_, region_)) {
    why = region_.in_front ? "probe out of view" : "probe not in front of the camera";
    return false;
  }
  diag_.radius_px = region_.radius_px;
  diag_.rim_in_view = region_.rim_in_image;
  if (region_.rim_in_image < config_.min_rim_in_view) {
    why = fmt::format("probe partly outside the image ({:.0f}% of its outline in view)", 100 * region_.rim_in_image);
    return false;
  }
  if (region_.radius_px < config_.min_radius_px) {
    why = fmt::format("probe too small on screen ({:.1f} px radius)", region_.radius_px);
    return false;
  }
  if (frame.width != model.width() || frame.height != model.height()) {
    why = "frame size differs from the camera model";
    return false;
  }
  if (!decode_linear_patch(frame, region_.rect, config_.response, patch_)) {
    why = "frame without usable pixels or exposure metadata";
    return false;
  }
  int clipped = 0, total = 0;
  for (const ProbeHit& h : region_.hits) {
    if (!patch_.rect.contains(h.x, h.y)) continue;
    ++total;
    clipped += patch_.clipped_at(h.x, h.y) ? 1 : 0;
  }
  if (total < 20) {
    why = "too few probe pixels in view";
    return false;
  }
  diag_.clipped_fraction = double(clipped) / total;
  if (diag_.clipped_fraction > config_.max_clipped_fraction) {
    why = fmt::format("probe over-exposed ({:.0f}% of its pixels clipped)", 100 * diag_.clipped_fraction);
    return false;
  }

  // Confidence: how much of the probe is seen, how big it is, how little is clipped, and how
  // clearly the light stands out (method-specific), each in [0, 1], multiplied.
  const double c_view = region_.rim_in_image;
  const double c_size = std::min(1.0, region_.radius_px / (2 * config_.min_radius_px));
  const double c_clip = std::clamp(1 - diag_.clipped_fraction / config_.max_clipped_fraction, 0.0, 1.0);
  double c_signal = 0;
  fresh.lights.clear();
  fresh.ambient_sh = {};
  std::vector<std::string> notes;
  switch (method_) {
    case ProbeMethod::BrightestImage:
    case ProbeMethod::BrightestSphere: {
      BrightestComponentsOptions o;
      o.max_lights = config_.max_lights;
      o.tolerance = config_.seed_tolerance;
      const BrightestComponentsResult r = method_ == ProbeMethod::BrightestImage
                               ? brightest_components_image(sphere, region_, patch_, model, T_cam_world, o)
                               : brightest_components_sphere(sphere, region_, patch_, model, T_cam_world, o);
      for (const BrightestComponent& c : r.components) {
        DirectionalLight l;
        l.direction_world = c.light_world;
        fresh.lights.push_back(l);
        diag_.light_clipped.push_back(c.clipped);
      }
      c_signal = r.components.empty() ? 0 : 1;
      notes.push_back("brightest-components method: light direction only, no irradiance or ambient");
      break;
    }
    case ProbeMethod::Environment: {
      MirrorProbeOptions o;
      o.max_lights = config_.max_lights;
      o.light_distance_m = config_.light_distance_m;
      const MirrorProbeResult r = analyse_mirror_probe(sphere, region_, patch_, o);
      for (const MirrorLight& m : r.lights) {
        fresh.lights.push_back(m.light);
        diag_.light_clipped.push_back(m.clipped);
      }
      fresh.ambient_sh = r.ambient_sh;
      // A peak 4x past the detection contrast counts as fully clear.
      c_signal = r.lights.empty() ? 0.5 : std::min(1.0, r.lights[0].peak_contrast / (4 * o.min_peak_contrast));
      if (r.lights.empty()) notes.push_back("no light stands out on the mirror: ambient only");
      break;
    }
    case ProbeMethod::Fit: {
      DiffuseFitOptions o;
      o.light_distance_m = config_.light_distance_m;
      o.fit_distance = config_.fit_light_distance;
      const DiffuseFitResult r = fit_diffuse_probe(sphere, region_, patch_, o);
      if (!r.ok) {
        why = "the diffuse fit failed (too few unclipped pixels, or no light on the probe)";
        return false;
      }
      fresh.lights.push_back(r.light);
      diag_.light_clipped.push_back(false);
      fresh.ambient_sh = r.ambient_sh;
      // Residual: 20% rms of the mean is no fit at all. Terminator: with it barely in view the
      // light's direction and the ambient's linear term trade off.
      const double both_sides = std::min(1.0, 5 * std::min(r.lit_fraction, 1 - r.lit_fraction));
      c_signal = std::clamp(1 - r.rms_residual / 0.2, 0.0, 1.0) * std::max(0.3, both_sides);
      break;
    }
    case ProbeMethod::Auto: break;  // resolved by configure
  }
  for (size_t i = 0; i < diag_.light_clipped.size(); ++i)
    if (diag_.light_clipped[i] && method_ == ProbeMethod::Environment)
      notes.push_back(fmt::format("light {} clipped: its irradiance is a lower bound", i));
  for (const DirectionalLight& l : fresh.lights) {
    diag_.raw_directions.push_back(l.direction_world);
    diag_.raw_irradiance.push_back(l.irradiance);
  }
  fresh.confidence = c_view * c_size * c_clip * c_signal;
  diag_.confidence = fresh.confidence;
  if (fresh.confidence < config_.min_confidence) {
    why = fmt::format("low confidence {:.2f} (factors: view {:.2f}, size {:.2f}, clipping {:.2f} with {:.0f}% of the "
                      "probe clipped, signal {:.2f})",
                      fresh.confidence, c_view, c_size, c_clip, 100 * diag_.clipped_fraction, c_signal);
    return false;
  }
  std::string note;
  for (const std::string& n : notes) note += (note.empty() ? "" : "; ") + n;
  fresh.note = note;
  return true;
}

void ProbeLightEstimator::blend(const LightEstimate& fresh, int64_t time_ns) {
  double alpha = 1;
  if (have_measurement_ && config_.smoothing_s > 0) {
    const double dt = std::clamp(double(time_ns - last_time_ns_) * 1e-9, 0.0, 10.0);
    alpha = 1 - std::exp(-dt / config_.smoothing_s);
    if (dt <= 0) alpha = 0.5;  // no timestamps: a fixed half-way step
  }
  std::vector<DirectionalLight> lights = fresh.lights;
  if (alpha < 1 && estimate_.lights.size() == lights.size()) {
    for (size_t i = 0; i < lights.size(); ++i) {
      const DirectionalLight& old = estimate_.lights[i];
      DirectionalLight& now = lights[i];
      // A light that jumped (another light became the strongest) is taken as it is.
      if (dot(old.direction_world, now.direction_world) < std::cos(0.5)) continue;
      const Vec3 d = (1 - alpha) * old.direction_world + alpha * now.direction_world;
      if (norm(d) > 0) now.direction_world = normalized(d);
      now.irradiance = (1 - alpha) * old.irradiance + alpha * now.irradiance;
      now.angular_diameter_rad = (1 - alpha) * old.angular_diameter_rad + alpha * now.angular_diameter_rad;
    }
    for (size_t k = 0; k < 9; ++k)
      estimate_.ambient_sh[k] = (1 - alpha) * estimate_.ambient_sh[k] + alpha * fresh.ambient_sh[k];
    estimate_.confidence = (1 - alpha) * estimate_.confidence + alpha * fresh.confidence;
  } else {
    estimate_.ambient_sh = fresh.ambient_sh;
    estimate_.confidence = fresh.confidence;
  }
  estimate_.lights = std::move(lights);
  estimate_.note = fresh.note;
  estimate_.state = LightState::Estimated;
  estimate_.frames_since_measured = 0;
  have_measurement_ = true;
  last_time_ns_ = time_ns;
}

LightEstimate ProbeLightEstimator::update(const Frame& frame, const CameraModel& model, const SE3& T_cam_world,
                                          bool pose_valid) noexcept {
  try {
    diag_ = {};
    if (!pose_valid) return hold("no valid camera pose");
    LightEstimate fresh;
    std::string why;
    if (!measure(frame, model, T_cam_world, fresh, why)) return hold(why);
    diag_.measured = true;
    blend(fresh, frame.meta.exposure_mid_ns());
    return estimate_;
  } catch (const std::exception& e) {
    return hold(std::string("probe analysis failed: ") + e.what());
  } catch (...) {
    return hold("probe analysis failed");
  }
}

}  // namespace arpipe
