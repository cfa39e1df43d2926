// Spec checks: one small rule per field, the message built from the item's label and the field name.
#include "core/physics/spec_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <variant>

#include "core/physics/physics_error.h"
#include "core/physics/physics_limits.h"

namespace arpipe {

namespace {

namespace lim = physics_limits;

[[noreturn]] void fail_spec_field(const std::string& who, const char* field, const std::string& expected) {
  throw PhysicsError(fmt::format("{}: {}: {}", who, field, expected));
}

void check_spec_number(const std::string& who, const char* field, double value, double lo, double hi,
                       const char* unit) {
  if (!std::isfinite(value) || value < lo || value > hi)
    fail_spec_field(who, field, fmt::format("must be a finite number in [{}, {}] {}, got {}", lo, hi, unit, value));
}

void check_spec_vector(const std::string& who, const char* field, const Vec3& v, double max_norm, const char* unit) {
  for (double c : v)
    if (!std::isfinite(c))
      fail_spec_field(who, field, fmt::format("must be finite, got ({}, {}, {})", v[0], v[1], v[2]));
  if (norm(v) > max_norm)
    fail_spec_field(who, field, fmt::format("must be at most {} {} long, got {}", max_norm, unit, norm(v)));
}

void check_spec_size(const std::string& who, const char* field, double value) {
  check_spec_number(who, field, value, lim::kMinSizeM, lim::kMaxSizeM, "m");
}

void check_spec_pose(const std::string& who, const char* field, const SE3& pose) {
  const Mat3& R = pose.rotation();
  for (const auto& row : R)
    for (double c : row)
      if (!std::isfinite(c)) fail_spec_field(who, field, "rotation must be finite");
  const Mat3 RtR = mat_mul(transpose(R), R);
  double worst = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) worst = std::max(worst, std::abs(RtR[i][j] - (i == j ? 1.0 : 0.0)));
  const double det = dot(R[0], cross(R[1], R[2]));
  if (worst > 1e-6 || det <= 0)
    fail_spec_field(who, field, fmt::format("rotation must be orthonormal with determinant +1 (off by {:.3g}, det {:.6g})",
                                            worst, det));
  check_spec_vector(who, field, pose.translation(), lim::kMaxCoordinateM, "m from the origin");
}

void check_spec_scale(const std::string& who, const Vec3& scale) {
  for (double s : scale)
    if (!std::isfinite(s) || s <= 0 || s > lim::kMaxSizeM)
      fail_spec_field(who, "shape.scale",
                      fmt::format("each component must be finite and in (0, {}], got ({}, {}, {})", lim::kMaxSizeM,
                                  scale[0], scale[1], scale[2]));
}

// The shapes both kinds of item share; a plane has nothing to check.
void check_spec_shape(const std::string& who, const SphereShape& s) { check_spec_size(who, "shape.radius_m", s.radius_m); }
void check_spec_shape(const std::string& who, const BoxShape& s) {
  for (double h : s.half_extents_m) check_spec_size(who, "shape.half_extents_m", h);
}
void check_spec_shape(const std::string& who, const CylinderShape& s) {
  check_spec_size(who, "shape.radius_m", s.radius_m);
  check_spec_size(who, "shape.half_height_m", s.half_height_m);
}
void check_spec_shape(const std::string& who, const MeshShape& s) {
  if (!s.mesh) fail_spec_field(who, "shape.mesh", "no mesh given");
  check_spec_scale(who, s.scale);
}
void check_spec_shape(const std::string&, const PlaneShape&) {}

void check_spec_surface(const std::string& who, double restitution, double friction, double rolling_friction) {
  check_spec_number(who, "restitution", restitution, 0, 1, "");
  check_spec_number(who, "friction", friction, 0, lim::kMaxFriction, "");
  check_spec_number(who, "rolling_friction", rolling_friction, 0, lim::kMaxFriction, "m");
}

}  // namespace

std::string physics_item_label(const char* what, size_t index, const std::string& name) {
  if (name.empty()) return fmt::format("{} {}", what, index);
  return fmt::format("{} {} (\"{}\")", what, index, name);
}

void check_world_settings(const RigidWorldSettings& s) {
  const std::string who = "physics settings";
  check_spec_vector(who, "gravity_mps2", s.gravity_mps2, 1000, "m/s^2");
  if (s.substep_hz < lim::kMinSubstepHz || s.substep_hz > lim::kMaxSubstepHz)
    fail_spec_field(who, "substep_hz",
                    fmt::format("must be in [{}, {}], got {}", lim::kMinSubstepHz, lim::kMaxSubstepHz, s.substep_hz));
  if (s.max_substeps_per_advance < 1 || s.max_substeps_per_advance > lim::kMaxSubstepsPerAdvance)
    fail_spec_field(who, "max_substeps_per_advance",
                    fmt::format("must be in [1, {}], got {}", lim::kMaxSubstepsPerAdvance, s.max_substeps_per_advance));
  if (s.history_ns < 0 || s.history_ns > lim::kMaxHistoryNs)
    fail_spec_field(who, "history_ns", fmt::format("must be in [0, {}] ns, got {}", lim::kMaxHistoryNs, s.history_ns));
  check_spec_number(who, "floor_limit_z_m", s.floor_limit_z_m, -lim::kMaxCoordinateM, lim::kMaxCoordinateM, "m");
  check_spec_number(who, "world_radius_m", s.world_radius_m, lim::kMinSizeM, lim::kMaxCoordinateM, "m");
  if (s.solver_iterations < 1 || s.solver_iterations > lim::kMaxSolverIterations)
    fail_spec_field(who, "solver_iterations",
                    fmt::format("must be in [1, {}], got {}", lim::kMaxSolverIterations, s.solver_iterations));
  check_spec_number(who, "sleep_linear_mps", s.sleep_linear_mps, 0, lim::kMaxSpeedMps, "m/s");
  check_spec_number(who, "sleep_angular_radps", s.sleep_angular_radps, 0, lim::kMaxAngularSpeedRadps, "rad/s");
}

void check_body_spec(const RigidBodySpec& spec, size_t index) {
  const std::string who = physics_item_label("body", index, spec.name);
  if (spec.kind != BodyKind::Static && spec.kind != BodyKind::Dynamic && spec.kind != BodyKind::Kinematic)
    fail_spec_field(who, "kind", "must be static, dynamic or kinematic");
  if (spec.kind == BodyKind::Dynamic)
    check_spec_number(who, "mass_kg", spec.mass_kg, lim::kMinMassKg, lim::kMaxMassKg, "kg (a dynamic body needs a mass)");
  check_spec_vector(who, "linear_velocity_mps", spec.linear_velocity_mps, lim::kMaxSpeedMps, "m/s");
  check_spec_vector(who, "angular_velocity_radps", spec.angular_velocity_radps, lim::kMaxAngularSpeedRadps, "rad/s");
  check_spec_surface(who, spec.restitution, spec.friction, spec.rolling_friction);
  check_spec_number(who, "linear_damping", spec.linear_damping, 0, 1, "per second");
  check_spec_number(who, "angular_damping", spec.angular_damping, 0, 1, "per second");
  std::visit([&](const auto& shape) { check_spec_shape(who, shape); }, spec.shape);
  if (const auto* mesh = std::get_if<MeshShape>(&spec.shape);
      mesh && mesh->collision == MeshCollision::Triangles && spec.kind == BodyKind::Dynamic)
    fail_spec_field(who, "shape.collision",
                    "a dynamic body cannot collide as triangles (concave); use the convex hull or a primitive");
  check_spec_pose(who, "T_body_shape", spec.T_body_shape);
  check_spec_pose(who, "T_world_body", spec.T_world_body);
  if (!spec.track.empty() && spec.kind != BodyKind::Kinematic)
    fail_spec_field(who, "track", "only a kinematic body follows a pose track");
  if (spec.track.size() > lim::kMaxTrackKeys)
    fail_spec_field(who, "track", fmt::format("at most {} poses, got {}", lim::kMaxTrackKeys, spec.track.size()));
  for (size_t i = 0; i < spec.track.size(); ++i) {
    const std::string field = fmt::format("track[{}]", i);
    check_spec_pose(who, field.c_str(), spec.track[i].T_world_body);
    if (i > 0 && spec.track[i].time_ns <= spec.track[i - 1].time_ns)
      fail_spec_field(who, field.c_str(),
                      fmt::format("times must increase strictly, got {} ns after {} ns", spec.track[i].time_ns,
                                  spec.track[i - 1].time_ns));
  }
}

void check_collider_spec(const ColliderSpec& spec, size_t index) {
  const std::string who = physics_item_label("collider", index, spec.name);
  std::visit([&](const auto& shape) { check_spec_shape(who, shape); }, spec.shape);
  check_spec_pose(who, "T_world_collider", spec.T_world_collider);
  check_spec_surface(who, spec.restitution, spec.friction, spec.rolling_friction);
}

}  // namespace arpipe
