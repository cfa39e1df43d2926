// How a RigidWorld steps and what it keeps: gravity, the fixed substep rate, the cap on substeps per
// advance, the span of substep states kept for pose queries, and the bounds of the world.
#pragma once

#include <cstdint>

#include "core/geometry/vec.h"

namespace arpipe {

struct RigidWorldSettings {
  // World (anchor) frame: z out of the tag's face, up when the tag lies on a table
  // (docs/DESIGN.md "Space"), so gravity is along -z. A tag on a wall needs another direction.
  Vec3 gravity_mps2{0, 0, -9.80665};
  // Fixed substeps per second. Each substep advances Bullet by exactly 1 / substep_hz seconds; the
  // k-th substep after the start belongs to t0 + floor(k * 1e9 / substep_hz) ns (exact, integer).
  int substep_hz = 960;
  // One advance_to runs at most this many substeps (default: 10 s at 960 Hz). A longer jump (a
  // replay that skips hours, a paused source) freezes the world over the rest: the bodies keep
  // their state and the substep grid restarts at the target time. Counted in the stats.
  int64_t max_substeps_per_advance = 9600;
  // Substep states kept behind the newest for pose_at (motion blur over an exposure, rolling-shutter
  // rows). Older queries get the oldest kept state, flagged clamped.
  int64_t history_ns = 500'000'000;
  // A dynamic body whose centre of mass goes below this world z, or further than world_radius_m
  // from the world origin, has left the world: it is removed and counted.
  double floor_limit_z_m = -10.0;
  double world_radius_m = 1'000.0;
  // Bullet's sequential-impulse iterations per substep. Bullet's 10 let a stack of five boxes lean
  // by 1.5 cm over 10 s awake; 30 hold it within 1.5 mm (tests/physics/stack_rest_test.cpp).
  int solver_iterations = 30;
  // A dynamic body slower than both for 2 s (Bullet's deactivation time) sleeps until touched.
  // Bullet's own defaults (0.8 m/s, 1 rad/s) would stop a slowly rolling ball.
  double sleep_linear_mps = 0.01;
  double sleep_angular_radps = 0.02;
};

}  // namespace arpipe
