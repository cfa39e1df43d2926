// Shared pieces of the physics tests: the ground, a ball, a box collider, and a walk over the
// world's substeps (each advance to 1 ns past the newest substep runs exactly one more).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

#include "core/physics/rigid_world.h"

namespace arpipe::physics_test {

inline constexpr double kG = 9.80665;
inline constexpr int64_t kStartNs = 1'000'000'000'000;  // an arbitrary CLOCK_MONOTONIC start

inline SE3 at(const Vec3& t) { return SE3(identity3(), t); }

inline ColliderSpec ground(double restitution = 1.0, double friction = 1.0) {
  ColliderSpec c;
  c.name = "ground";
  c.restitution = restitution;
  c.friction = friction;
  return c;
}

inline ColliderSpec box_collider(const Vec3& centre, const Vec3& half_extents, double restitution = 1.0,
                                 double friction = 1.0) {
  ColliderSpec c;
  c.name = "box";
  c.shape = BoxShape{half_extents};
  c.T_world_collider = at(centre);
  c.restitution = restitution;
  c.friction = friction;
  return c;
}

inline RigidBodySpec ball(const Vec3& centre, double radius, double restitution, double friction = 0.5) {
  RigidBodySpec b;
  b.name = "ball";
  b.kind = BodyKind::Dynamic;
  b.mass_kg = 0.2;
  b.shape = SphereShape{radius};
  b.T_world_body = at(centre);
  b.restitution = restitution;
  b.friction = friction;
  return b;
}

// Calls visit(t_ns) after each substep until `seconds` after the start have been simulated.
inline void each_substep(RigidWorld& world, double seconds, const std::function<void(int64_t)>& visit) {
  if (!world.started()) world.start(kStartNs);
  const auto end_ns = kStartNs + static_cast<int64_t>(seconds * 1e9);
  while (world.newest_ns() < end_ns) {
    world.advance_to(world.newest_ns() + 1);
    visit(world.newest_ns());
  }
}

// A measured error, printed (ctest --output-on-failure -V shows it) and kept in the XML report.
inline void report_measured(const std::string& key, double value) {
  testing::Test::RecordProperty(key, std::to_string(value));
  std::printf("[ measured ] %s = %.6g\n", key.c_str(), value);
}

inline double seconds_since_start(int64_t t_ns) { return static_cast<double>(t_ns - kStartNs) * 1e-9; }

}  // namespace arpipe::physics_test
