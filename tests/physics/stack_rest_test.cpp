// A stack of boxes on the ground stays at rest: over 10 s no box's centre drifts more than 1 mm and
// none turns more than 1 mrad, with Bullet's sleeping (the default) and without it (2 mm, 5 mrad).
#include <gtest/gtest.h>

#include <vector>

#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

struct Drift {
  double position_m = 0;
  double angle_rad = 0;
};

Drift stack_drift(const RigidWorldSettings& settings, int boxes) {
  constexpr double half = 0.05;
  RigidWorld world(settings);
  world.add_collider(ground(0.0, 0.8));
  std::vector<SE3> initial;
  for (int i = 0; i < boxes; ++i) {
    RigidBodySpec box;
    box.name = "box" + std::to_string(i);
    box.mass_kg = 0.5;
    box.restitution = 0;
    box.friction = 0.8;
    box.shape = BoxShape{{half, half, half}};
    // Each a little turned about z and offset, as a real stack would be.
    box.T_world_body = SE3(rotation_from_vector({0, 0, 0.05 * i}), {0.004 * i, -0.003 * i, half + 2 * half * i});
    initial.push_back(box.T_world_body);
    world.add_body(box);
  }
  world.start(kStartNs);
  world.advance_to(kStartNs + 10'000'000'000);
  Drift d;
  for (int i = 0; i < boxes; ++i) {
    const BodySample s = world.sample_at(static_cast<size_t>(i), world.newest_ns());
    EXPECT_TRUE(s.present);
    d.position_m = std::max(d.position_m, norm(s.T_world_body.translation() - initial[static_cast<size_t>(i)].translation()));
    d.angle_rad = std::max(d.angle_rad, rotation_angle_between(s.T_world_body, initial[static_cast<size_t>(i)]));
  }
  return d;
}

TEST(StackRest, FiveBoxesStayPutForTenSeconds) {
  const Drift d = stack_drift({}, 5);
  EXPECT_LT(d.position_m, 1e-3);
  EXPECT_LT(d.angle_rad, 1e-3);
  report_measured("drift_m", d.position_m);
  report_measured("turn_rad", d.angle_rad);
}

TEST(StackRest, FiveBoxesStayPutWithoutSleeping) {
  RigidWorldSettings awake;
  awake.sleep_linear_mps = 0;
  awake.sleep_angular_radps = 0;
  const Drift d = stack_drift(awake, 5);
  EXPECT_LT(d.position_m, 2e-3);
  EXPECT_LT(d.angle_rad, 5e-3);
  report_measured("drift_m", d.position_m);
  report_measured("turn_rad", d.angle_rad);
}

}  // namespace
}  // namespace arpipe
