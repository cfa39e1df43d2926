// Seed 003's scene C in small: a ball thrown at a real box (a collide proxy) bounces off its side
// with the combined restitution (within 1 %), never gets more than one substep's travel into it,
// and comes to rest on the ground.
#include <gtest/gtest.h>

#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

TEST(SceneC, AThrownBallBouncesOffARealBox) {
  constexpr double r = 0.04, e = 0.7, face_x = 0.9;
  RigidWorldSettings settings;
  settings.history_ns = 1'000'000'000;
  RigidWorld world(settings);
  world.add_collider(ground(1.0, 0.8));
  world.add_collider(box_collider({1.0, 0, 0.2}, {0.1, 0.4, 0.2}));  // its -x face at x = 0.9, top at 0.4
  RigidBodySpec thrown = ball({0, 0, 0.3}, r, e, 0.0);  // frictionless: no spin to muddle the bounce
  thrown.linear_velocity_mps = {4.0, 0, 1.0};
  const size_t id = world.add_body(thrown);
  double vx_before = 0, vx_after = 0, max_x = -1;
  bool hit = false;
  each_substep(world, 4.0, [&](int64_t t) {
    const BodySample s = world.sample_at(id, t);
    max_x = std::max(max_x, s.T_world_body.translation()[0]);
    if (!hit && s.linear_velocity_mps[0] < 0) {
      hit = true;
      vx_after = s.linear_velocity_mps[0];
      // The hit is at z = 0.3 + t - g t^2 / 2 with t = (0.9 - r - 0) / 4: below the box's top.
      EXPECT_LT(s.T_world_body.translation()[2], 0.4);
    }
    if (!hit) vx_before = s.linear_velocity_mps[0];
  });
  ASSERT_TRUE(hit);
  EXPECT_NEAR(vx_before, 4.0, 1e-4);
  EXPECT_NEAR(vx_after, -e * vx_before, 0.01 * e * vx_before);
  report_measured("rebound_relative_error", vx_after / (-e * vx_before) - 1);
  report_measured("deepest_into_box_m", max_x - (face_x - r));
  // Contacts are found at the start of a substep: the ball can be one substep's travel into the
  // box before it is pushed back (by the split impulse, which adds no velocity).
  const double substep_travel = 4.0 / settings.substep_hz;
  EXPECT_LT(max_x, face_x - r + substep_travel + 1e-3);
  const BodySample end = world.sample_at(id, world.newest_ns());
  EXPECT_TRUE(end.present);
  EXPECT_NEAR(end.T_world_body.translation()[2], r, 1e-3);
  EXPECT_LT(end.T_world_body.translation()[0], face_x - r);
}

}  // namespace
}  // namespace arpipe
