// A ball dropped onto the ground against the closed forms: it lands at sqrt(2h/g) within one
// substep, bounces to e^2 h within 1 %, and pose_at between substeps stays within the stated
// bound of z0 - g t^2 / 2 (also for the orientation of a spinning ball).
#include <gtest/gtest.h>

#include <cmath>

#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

struct DropResult {
  double landing_s = -1;       // the first substep at which the ball's bottom reaches the ground
  double rebound_s = -1;       // the first substep after which it moves up
  double bounce_height_m = 0;  // the ball's bottom at the top of the first bounce
};

DropResult drop_ball(double h, double e, const RigidWorldSettings& settings = {}, const ColliderSpec& floor = ground()) {
  constexpr double r = 0.05;
  RigidWorld world(settings);
  world.add_collider(floor);
  const size_t id = world.add_body(ball({0, 0, h + r}, r, e));
  DropResult out;
  bool falling_again = false;
  each_substep(world, 2.5, [&](int64_t t) {
    const BodySample s = world.sample_at(id, t);
    if (out.landing_s < 0 && s.T_world_body.translation()[2] - r <= 0) out.landing_s = seconds_since_start(t);
    if (out.rebound_s < 0) {
      if (s.linear_velocity_mps[2] > 0) out.rebound_s = seconds_since_start(t);
      return;
    }
    if (falling_again) return;
    out.bounce_height_m = std::max(out.bounce_height_m, s.T_world_body.translation()[2] - r);
    if (s.linear_velocity_mps[2] < 0) falling_again = true;
  });
  return out;
}

// Contacts are found at the start of a substep, so the ball's velocity turns round in the substep
// after the one that took it to the ground: at most one substep after it lands.
TEST(FreeFall, LandsAtTheClosedFormTimeWithinOneSubstep) {
  const RigidWorldSettings settings;
  const double dt = 1.0 / settings.substep_hz;
  for (double h : {0.25, 1.0, 3.0}) {
    const DropResult r = drop_ball(h, 0.5);
    const double expected = std::sqrt(2 * h / kG);
    EXPECT_NEAR(r.landing_s, expected, dt) << "h = " << h << " m";
    EXPECT_GE(r.rebound_s, r.landing_s) << "h = " << h << " m";
    EXPECT_LE(r.rebound_s, r.landing_s + dt + 1e-9) << "h = " << h << " m";
    report_measured("landing_error_substeps_h" + std::to_string(static_cast<int>(h * 100)), (r.landing_s - expected) / dt);
  }
}

// Bullet combines restitutions by their product: the ground's 1 times the ball's e. The velocity
// right after the bounce is e times the velocity before, so the height is e^2 h.
TEST(FreeFall, BounceHeightFollowsTheRestitutionWithinOnePercent) {
  for (double h : {0.25, 1.0, 3.0})
    for (double e : {0.3, 0.6, 0.9}) {
      const DropResult r = drop_ball(h, e);
      EXPECT_NEAR(r.bounce_height_m, e * e * h, 0.01 * e * e * h) << "h = " << h << " m, e = " << e;
      report_measured("bounce_relative_error_h" + std::to_string(static_cast<int>(h * 100)) + "_e" +
                          std::to_string(static_cast<int>(e * 10)),
                      r.bounce_height_m / (e * e * h) - 1);
    }
}

// Where within a substep the ball meets the ground changes how deep it gets before the contact is
// found: drops from 60 heights a fraction of a substep apart all stay within 1 %.
TEST(FreeFall, BounceHeightHoldsWhereverTheContactFallsInASubstep) {
  double worst = 0;
  for (int i = 0; i < 60; ++i) {
    const double h = 0.5 + 0.0037 * i, e = 0.5;
    const DropResult r = drop_ball(h, e);
    const double error = r.bounce_height_m / (e * e * h) - 1;
    EXPECT_LT(std::abs(error), 0.01) << "h = " << h << " m";
    worst = std::max(worst, std::abs(error));
  }
  report_measured("worst_bounce_relative_error", worst);
}

TEST(FreeFall, TheCombinedRestitutionIsTheProduct) {
  const double h = 1.0;
  const DropResult r = drop_ball(h, 0.8, {}, ground(0.5));
  const double e = 0.8 * 0.5;
  EXPECT_NEAR(r.bounce_height_m, e * e * h, 0.01 * e * e * h);
}

TEST(FreeFall, ATriangleMeshGroundBouncesLikeThePlane) {
  auto plane = std::make_shared<Mesh>();
  plane->positions = {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0};
  plane->indices = {0, 1, 2, 0, 2, 3};
  ColliderSpec floor = ground();
  floor.shape = MeshShape{plane, {1, 1, 1}, MeshCollision::Triangles};
  const double h = 1.0, e = 0.6;
  const DropResult r = drop_ball(h, e, {}, floor);
  EXPECT_NEAR(r.landing_s, std::sqrt(2 * h / kG), 1.0 / RigidWorldSettings{}.substep_hz);
  EXPECT_NEAR(r.bounce_height_m, e * e * h, 0.01 * e * e * h);
}

// Bullet integrates semi-implicitly (v += g dt, then x += v dt), so after k substeps the ball has
// fallen g dt^2 k (k + 1) / 2, ahead of the closed form by g t dt / 2; between substeps the
// interpolation follows the chord, off the parabola by at most g dt^2 / 8. Together:
// |z(t) - (z0 - g t^2 / 2)| <= g dt t / 2 + g dt^2 / 8, plus single-precision rounding (5e-5 m).
TEST(FreeFall, PoseBetweenSubstepsIsWithinTheStatedBoundOfTheClosedForm) {
  RigidWorldSettings settings;
  settings.history_ns = 2'000'000'000;
  const double dt = 1.0 / settings.substep_hz;
  RigidWorld world(settings);
  const double z0 = 5.0;
  const size_t id = world.add_body(ball({0, 0, z0}, 0.05, 0.5));
  world.start(kStartNs);
  world.advance_to(kStartNs + 600'000'000);
  double worst_excess = -1;
  for (int i = 0; i <= 1000; ++i) {
    const double t = 0.6 * i / 1000.0;
    const BodySample s = world.sample_at(id, kStartNs + static_cast<int64_t>(std::llround(t * 1e9)));
    ASSERT_TRUE(s.present);
    ASSERT_FALSE(s.clamped);
    const double error = std::abs(s.T_world_body.translation()[2] - (z0 - 0.5 * kG * t * t));
    const double bound = kG * dt * t / 2 + kG * dt * dt / 8 + 5e-5;
    EXPECT_LE(error, bound) << "t = " << t;
    worst_excess = std::max(worst_excess, error - bound);
    EXPECT_NEAR(s.linear_velocity_mps[2], -kG * t, kG * dt + 1e-4) << "t = " << t;
  }
  report_measured("worst_error_minus_bound_m", worst_excess);
}

// A sphere spinning about a fixed axis keeps its angular velocity (isotropic inertia, no torque),
// and slerp between substeps is exact for a constant axis: angle = w t.
TEST(FreeFall, OrientationBetweenSubstepsFollowsAConstantSpin) {
  RigidWorldSettings settings;
  settings.gravity_mps2 = {0, 0, 0};
  settings.history_ns = 2'000'000'000;
  RigidWorld world(settings);
  RigidBodySpec spinning = ball({0, 0, 1}, 0.05, 0.5);
  const double w = 7.0;  // rad/s about z
  spinning.angular_velocity_radps = {0, 0, w};
  const size_t id = world.add_body(spinning);
  world.start(kStartNs);
  world.advance_to(kStartNs + 400'000'000);
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.4 * i / 400.0;
    const SE3 pose = world.pose_at(id, kStartNs + static_cast<int64_t>(std::llround(t * 1e9)));
    const SE3 expected(rotation_from_vector({0, 0, w * t}), {0, 0, 1});
    EXPECT_LT(rotation_angle_between(pose, expected), 1e-4) << "t = " << t;
    EXPECT_LT(norm(pose.translation() - Vec3{0, 0, 1}), 1e-6);
  }
}

}  // namespace
}  // namespace arpipe
