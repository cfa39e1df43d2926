// Omnidirectional stereo against its definition and closed forms: each ray leaves its eye on the
// circle, perpendicular to the ray's horizontal part and left of it for the left eye; a point is
// where its eye's ray through it says.
#include "core/geometry/ods_projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace arpipe {
namespace {

constexpr double kDeg = std::numbers::pi / 180;
const Vec3 kUp{0, 0, 1};

TEST(OdsProjection, TheEyesComeTogetherOverThePoleMergeAngles) {
  const OdsRig rig{0.064, 60 * kDeg, 75 * kDeg};
  EXPECT_DOUBLE_EQ(ods_eye_radius(rig, 0), 0.032);
  EXPECT_DOUBLE_EQ(ods_eye_radius(rig, -60 * kDeg), 0.032);
  EXPECT_NEAR(ods_eye_radius(rig, 67.5 * kDeg), 0.016, 1e-15);  // the raised cosine's middle
  EXPECT_NEAR(ods_eye_radius(rig, -67.5 * kDeg), 0.016, 1e-15);
  EXPECT_DOUBLE_EQ(ods_eye_radius(rig, 75 * kDeg), 0);
  EXPECT_DOUBLE_EQ(ods_eye_radius(rig, 90 * kDeg), 0);
  // Equal angles: a step.
  const OdsRig step{0.064, 70 * kDeg, 70 * kDeg};
  EXPECT_DOUBLE_EQ(ods_eye_radius(step, 69.9 * kDeg), 0.032);
  EXPECT_DOUBLE_EQ(ods_eye_radius(step, 70.1 * kDeg), 0);
}

TEST(OdsProjection, EachRayLeavesItsEyeOnTheCircleLeftOrRightOfIt) {
  const OdsRig rig;
  // Looking along +y (x to the right, z up): the left eye at -x, the right at +x.
  const Vec3 left = ods_eye_origin(rig, Eye::Left, kUp, {0, 1, 0});
  const Vec3 right = ods_eye_origin(rig, Eye::Right, kUp, {0, 1, 0});
  EXPECT_NEAR(left[0], -0.032, 1e-15);
  EXPECT_NEAR(right[0], 0.032, 1e-15);
  EXPECT_NEAR(norm(Vec3{left[1], left[2], right[1]}), 0, 1e-15);
  // Up 30 degrees, turned: still horizontal, perpendicular to the ray's horizontal part.
  const Vec3 d = normalized(Vec3{std::cos(30 * kDeg) * std::sin(40 * kDeg), std::cos(30 * kDeg) * std::cos(40 * kDeg), std::sin(30 * kDeg)});
  const Vec3 o = ods_eye_origin(rig, Eye::Left, kUp, d);
  EXPECT_NEAR(norm(o), 0.032, 1e-15);
  EXPECT_NEAR(o[2], 0, 1e-15);
  EXPECT_NEAR(dot(o, d), 0, 1e-15);
  EXPECT_GT(dot(cross(d, o), kUp), 0);  // left: turning from the ray to the eye is anticlockwise seen from above
  // A mono view and a ray along the axis have no offset.
  EXPECT_EQ(norm(ods_eye_origin(rig, Eye::Mono, kUp, d)), 0);
  EXPECT_EQ(norm(ods_eye_origin(rig, Eye::Left, kUp, kUp)), 0);
}

TEST(OdsProjection, APointAheadIsSeenTurnedByTheArcsineOfTheEyeOverItsDistance) {
  // A point 1.2 m ahead on the horizon: each eye's ray through it is tangent to the circle, so it
  // turns from straight ahead by asin(r / 1.2), the left eye's to the right.
  const OdsRig rig;
  for (const Eye eye : {Eye::Left, Eye::Right}) {
    const Vec3 q = ods_eye_point(rig, eye, kUp, {0, 1.2, 0});
    const double azimuth = std::atan2(q[0], q[1]);  // to the right of +y
    EXPECT_NEAR(azimuth, (eye == Eye::Left ? 1 : -1) * std::asin(0.032 / 1.2), 1e-15);
    EXPECT_NEAR(norm(q), std::sqrt(1.2 * 1.2 - 0.032 * 0.032), 1e-15);  // the distance from the eye
  }
  // 40 degrees up, at 0.8 m horizontally: elevation atan(h / sqrt(rho^2 - r^2)).
  const Vec3 p{0, 0.8, 0.8 * std::tan(40 * kDeg)};
  const Vec3 q = ods_eye_point(rig, Eye::Left, kUp, p);
  EXPECT_NEAR(std::atan2(q[2], std::hypot(q[0], q[1])), std::atan(p[2] / std::sqrt(0.64 - 0.032 * 0.032)), 1e-15);
  EXPECT_EQ(ods_eye_point(rig, Eye::Mono, kUp, p), p);
}

TEST(OdsProjection, EveryPointLiesOnItsEyesRayInsideThePoleMerge) {
  // Random points 0.3 to 20 m away at every elevation, either eye, any axis: p = o(d) + |q| d for
  // the q the function gives (d = q / |q|), to a micrometre, including where the taper moves the
  // eye with the ray's elevation (the fixed point).
  const OdsRig rig;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1, 1), distance(0.3, 20);
  const Vec3 up = normalized(Vec3{0.1, -0.2, 1});
  double worst = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 direction{unit(rng), unit(rng), unit(rng)};
    if (norm(direction) < 0.1) continue;
    const Vec3 p = distance(rng) * normalized(direction);
    for (const Eye eye : {Eye::Left, Eye::Right}) {
      const Vec3 q = ods_eye_point(rig, eye, up, p);
      const Vec3 d = normalized(q);
      const Vec3 back = ods_eye_origin(rig, eye, up, d) + norm(q) * d;
      worst = std::max(worst, norm(back - p));
    }
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(OdsProjection, APointInsideTheEyesCircleStaysFiniteAndNearby) {
  // 1.4 cm from the axis, inside the 3.2 cm circle: no ray passes through it; it is drawn no
  // further than the eye's offset from where it is.
  const OdsRig rig;
  const Vec3 p{0.01, 0.01, 0.002};
  for (const Eye eye : {Eye::Left, Eye::Right}) {
    const Vec3 q = ods_eye_point(rig, eye, kUp, p);
    EXPECT_TRUE(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2]));
    EXPECT_LE(norm(q - p), 0.032 + 1e-15);
  }
}

}  // namespace
}  // namespace arpipe
