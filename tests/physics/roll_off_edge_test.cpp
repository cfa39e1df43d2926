// A ball moving along a box's top leaves it at the edge and lands where the projectile closed form
// says. At v^2 / r > g the ball cannot follow the edge round, so it leaves as its centre passes
// the edge, horizontally at v, and falls the box's height H: x = edge + v sqrt(2H / g).
// Tolerances: the leave point (the apex of the free-flight parabola, extrapolated back from 5 cm
// below the top) within one substep's travel (v dt) plus 1 mm; the landing point (the first
// substep at which the ball touches the ground) within two substeps' travel plus 1 mm.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

struct EdgeRun {
  double leave_x = -1;  // where the free-flight parabola is horizontal: the point the ball left from
  double land_x = -1;   // the first substep at which the ball's bottom reaches the ground
};

// Box top at z = H, its +x edge at x = 0.5; the ball starts resting on the top at x = 0.
EdgeRun run_off_edge(double v, double friction, bool rolling) {
  constexpr double H = 0.5, r = 0.05;
  RigidWorld world;
  world.add_collider(ground(1.0, 1.0));
  world.add_collider(box_collider({0, 0, H / 2}, {0.5, 0.5, H / 2}, 1.0, 1.0));
  RigidBodySpec b = ball({0, 0, H + r}, r, 0.5, friction);
  b.linear_velocity_mps = {v, 0, 0};
  if (rolling) b.angular_velocity_radps = {0, v / r, 0};  // no slip at the contact
  const size_t id = world.add_body(b);
  EdgeRun out;
  each_substep(world, 1.0, [&](int64_t t) {
    const BodySample s = world.sample_at(id, t);
    const Vec3 p = s.T_world_body.translation();
    // 5 cm down, well clear of the edge: back along the parabola to where it was horizontal.
    if (out.leave_x < 0 && p[2] < H + r - 0.05) out.leave_x = p[0] - s.linear_velocity_mps[0] * (-s.linear_velocity_mps[2] / kG);
    if (out.land_x < 0 && p[2] - r <= 0) out.land_x = p[0];
  });
  return out;
}

void expect_projectile(double v, double friction, bool rolling) {
  constexpr double H = 0.5, edge = 0.5;
  const double dt = 1.0 / RigidWorldSettings{}.substep_hz;
  const EdgeRun run = run_off_edge(v, friction, rolling);
  EXPECT_NEAR(run.leave_x, edge, v * dt + 1e-3);
  const double land_x = edge + v * std::sqrt(2 * H / kG);
  EXPECT_NEAR(run.land_x, land_x, 2 * v * dt + 1e-3);
  report_measured("leave_error_m", run.leave_x - edge);
  report_measured("land_error_m", run.land_x - land_x);
}

TEST(RollOffEdge, SlidingWithoutFrictionLeavesAtTheEdgeAndLandsOnTheParabola) { expect_projectile(2.0, 0.0, false); }

TEST(RollOffEdge, RollingLeavesAtTheEdgeAndLandsOnTheParabola) { expect_projectile(2.0, 0.5, true); }

TEST(RollOffEdge, AFasterBallLandsFurther) { expect_projectile(3.5, 0.0, false); }

// With friction a ball that starts sliding without spin ends up rolling at 5/7 of its speed
// (solid sphere: v_roll = v0 / (1 + I / (m r^2)) = 5 v0 / 7).
TEST(RollOffEdge, ASlidingBallWithFrictionSettlesIntoRollingAtFiveSevenths) {
  constexpr double r = 0.05;
  RigidWorld world;
  world.add_collider(ground(1.0, 1.0));
  RigidBodySpec b = ball({0, 0, r}, r, 0.0, 0.5);
  b.linear_velocity_mps = {2.0, 0, 0};
  const size_t id = world.add_body(b);
  world.start(kStartNs);
  world.advance_to(kStartNs + 1'500'000'000);
  const BodySample s = world.sample_at(id, world.newest_ns());
  EXPECT_NEAR(s.linear_velocity_mps[0], 2.0 * 5 / 7, 0.01 * 2.0 * 5 / 7);
  EXPECT_NEAR(s.angular_velocity_radps[1] * r, s.linear_velocity_mps[0], 0.01);
}

}  // namespace
}  // namespace arpipe
