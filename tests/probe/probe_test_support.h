// Shared by the probe tests: the probe-indoor capture (configs/sim/probe-indoor.toml) with its
// ground truth, the two probes as the scene places them, and angle helpers.
#pragma once

#include <cmath>
#include <numbers>
#include <string>

#include "capture/recording/recording_reader.h"
#include "core/probe/probe_sphere.h"

namespace arpipe::probe_test {

inline std::string capture_dir() { return std::string(ARPIPE_BINARY_DIR) + "/probe-indoor-capture"; }

// configs/sim/probe-indoor.toml: the mirror (specular reflectance 0.9) and the diffuse probe
// (albedo 0.7), both r 0.04 m resting on the table.
inline ProbeSphere mirror_probe() { return {ProbeSphere::Kind::Mirror, {-0.15, 0.10, 0.0395}, 0.04, 0.9}; }
inline ProbeSphere diffuse_probe() { return {ProbeSphere::Kind::Diffuse, {0.15, 0.16, 0.0395}, 0.04, 0.7}; }
// The simulator's default sensor sensitivity (docs/SIMULATOR.md): scene-linear = radiance * 100.
inline constexpr double kSensitivity = 100.0;

inline const GroundTruthLight& key_light(const GroundTruthFrame& truth) {
  for (const GroundTruthLight& l : truth.lights)
    if (l.name == "key") return l;
  return truth.lights.front();
}

inline Vec3 true_direction(const GroundTruthFrame& truth, const ProbeSphere& probe) {
  return normalized(key_light(truth).position - probe.center_world);
}

inline double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(norm(cross(a, b)), dot(a, b)) * 180 / std::numbers::pi;
}

}  // namespace arpipe::probe_test
