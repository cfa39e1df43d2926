// SE(3) interpolation and extrapolation of camera poses: exact end points, analytic constant-
// velocity motions (rebuilt exactly from two samples), near-180-degree, tiny and huge motions,
// and the difference between the centre-line and the screw model.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/se3_interpolation.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr PoseInterpolation kMethods[] = {PoseInterpolation::CentreLine, PoseInterpolation::Screw};

Vec3 centre(const SE3& T_cam_world) { return T_cam_world.inverse().translation(); }

double angle_between(const SE3& a, const SE3& b) { return rotation_angle_between(a, b); }
double centre_distance(const SE3& a, const SE3& b) { return norm(centre(a) - centre(b)); }
double rotation_orthonormality_error(const Mat3& R) {
  const Mat3 I = mat_mul(R, transpose(R));
  double e = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e = std::max(e, std::abs(I[i][j] - (i == j ? 1.0 : 0.0)));
  return e;
}

Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  return normalized(Vec3{n(rng), n(rng), n(rng)});
}

SE3 random_pose(std::mt19937_64& rng, double max_translation = 3) {
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_real_distribution<double> t(-max_translation, max_translation);
  return SE3::from_rt(kPi * u(rng) * random_unit(rng), {t(rng), t(rng), t(rng)});
}

// A camera moving at constant velocity in the centre-line model: centre c0 + v t, orientation
// R_world_cam(t) = R0 exp(t w) (w in the camera frame).
SE3 centre_line_motion(const SE3& T_world_cam0, const Vec3& v, const Vec3& w, double t) {
  const SE3 T_world_cam(mat_mul(T_world_cam0.rotation(), rotation_from_vector(t * w)),
                        T_world_cam0.translation() + t * v);
  return T_world_cam.inverse();
}

TEST(Se3Interpolation, EndPointsAreExactForEveryMethodAndAngle) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 500; ++i) {
    const SE3 a = random_pose(rng);
    // A third of the pairs are 180 degrees minus 1e-9 .. 1e-3 apart, the delicate case for the logs.
    SE3 b = random_pose(rng);
    if (i % 3 == 0)
      b = a * SE3::from_rt((kPi - std::pow(10.0, -9 + 6 * double(i % 7) / 6)) * random_unit(rng), {0.5, -1, 2});
    for (const PoseInterpolation method : kMethods) {
      const SE3 at0 = interpolate_camera_pose(a, b, 0.0, method);
      const SE3 at1 = interpolate_camera_pose(a, b, 1.0, method);
      // Rounding only: a few ulps of the rotation entries (1) and of translations up to ~5 m.
      EXPECT_LT(angle_between(at0, a), 1e-13);
      EXPECT_LT(angle_between(at1, b), 1e-13);
      EXPECT_LT(norm(at0.translation() - a.translation()), 1e-13);
      EXPECT_LT(norm(at1.translation() - b.translation()), 1e-13);
    }
  }
}

TEST(Se3Interpolation, ConstantVelocityMotionIsRebuiltExactlyFromTwoPoses) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const SE3 T_world_cam0 = random_pose(rng).inverse();
    const Vec3 v{u(rng), u(rng), u(rng)};  // m/s
    const Vec3 w = 6.0 * u(rng) * random_unit(rng);  // up to 6 rad/s, a fast hand
    const int64_t t1 = 1'000'000'000, t2 = t1 + 33'333'333;  // 30 fps
    const TimedPose a{t1, centre_line_motion(T_world_cam0, v, w, 0.0)};
    const TimedPose b{t2, centre_line_motion(T_world_cam0, v, w, 0.033333333)};
    // Inside the interval, and beyond it on either side (a frame's exposure end is extrapolated
    // up to about half a frame past its pose).
    for (const int64_t t : {t1 - 20'000'000, t1 + 4'000'000, t2, t2 + 4'000'000, t2 + 16'000'000, t2 + 33'333'333}) {
      const SE3 truth = centre_line_motion(T_world_cam0, v, w, double(t - t1) * 1e-9);
      const SE3 estimate = pose_at_time(a, b, t);
      // Exact maths; rounding of a few 1e-16 amplified by |s| <= 2 and by the ns clock.
      EXPECT_LT(angle_between(estimate, truth), 1e-12);
      EXPECT_LT(centre_distance(estimate, truth), 1e-12);
    }
  }
}

TEST(Se3Interpolation, ScrewRebuildsAConstantTwistExactly) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const SE3 T0 = random_pose(rng);
    const Vec6 twist{u(rng), u(rng), u(rng), 3 * u(rng), 3 * u(rng), 3 * u(rng)};  // per second
    const auto at = [&](double t) {
      Vec6 x{};
      for (size_t k = 0; k < 6; ++k) x[k] = t * twist[k];
      return T0 * SE3::exp(x);
    };
    const TimedPose a{0, at(0.0)}, b{33'000'000, at(0.033)};
    for (const double t : {-0.01, 0.004, 0.02, 0.045, 0.066}) {
      const SE3 estimate = pose_at_time(a, b, std::llround(t * 1e9), PoseInterpolation::Screw);
      EXPECT_LT(angle_between(estimate, at(t)), 1e-12);
      EXPECT_LT(norm(estimate.translation() - at(t).translation()), 1e-12);
    }
  }
}

TEST(Se3Interpolation, PureRotationAboutTheCentreIsTheSameInBothModels) {
  // tag-pan's camera turns in place: both models keep the centre fixed and turn at constant rate.
  const SE3 T_world_cam0 = SE3::from_rt({0.3, -0.2, 0.1}, {0, -0.3, 0.4});
  const Vec3 w{0.1, 2.0, -0.3};
  const SE3 a = centre_line_motion(T_world_cam0, {0, 0, 0}, w, 0.0);
  const SE3 b = centre_line_motion(T_world_cam0, {0, 0, 0}, w, 0.033);
  for (const double s : {-0.5, 0.25, 0.5, 1.5}) {
    const SE3 truth = centre_line_motion(T_world_cam0, {0, 0, 0}, w, s * 0.033);
    for (const PoseInterpolation method : kMethods) {
      const SE3 estimate = interpolate_camera_pose(a, b, s, method);
      EXPECT_LT(angle_between(estimate, truth), 1e-14);
      EXPECT_LT(centre_distance(estimate, truth), 1e-14);
    }
  }
}

TEST(Se3Interpolation, CentreLineKeepsAStraightWalkStraightWhereTheScrewBends) {
  // The camera walks 1 m along x while turning 90 degrees about its y axis. Halfway, its centre is
  // at 0.5 m on the line; the screw about the turn's axis puts it on an arc instead.
  const SE3 a = SE3::identity();
  const SE3 T_world_cam_b = SE3::from_rt({0, kPi / 2, 0}, {1, 0, 0});
  const SE3 b = T_world_cam_b.inverse();
  const SE3 line = interpolate_camera_pose(a, b, 0.5, PoseInterpolation::CentreLine);
  const SE3 screw = interpolate_camera_pose(a, b, 0.5, PoseInterpolation::Screw);
  EXPECT_LT(norm(centre(line) - Vec3{0.5, 0, 0}), 1e-15);
  EXPECT_NEAR(angle_between(line, a), kPi / 4, 1e-15);
  EXPECT_NEAR(angle_between(screw, a), kPi / 4, 1e-15);  // the rotations agree
  // Screw: the relative motion is a pure rotation by 90 degrees about a y axis through the point
  // p with p - Ry(90)p = (1, 0, 0), so p = (0.5, 0, -0.5); halfway, the centre sits at
  // p + Ry(45)(0 - p) = (0.5, 0, sqrt(0.5) - 0.5), 0.21 m off the straight walk.
  const double r = std::sqrt(0.5);
  const Vec3 p{0.5, 0, -0.5};
  const double h = kPi / 4;
  const Vec3 from_p = Vec3{0, 0, 0} - p;  // (-0.5, 0, 0.5)
  const Vec3 expected = p + Vec3{std::cos(h) * from_p[0] + std::sin(h) * from_p[2], 0,
                                 -std::sin(h) * from_p[0] + std::cos(h) * from_p[2]};
  EXPECT_NEAR(norm(from_p), r, 1e-15);
  EXPECT_LT(norm(centre(screw) - expected), 1e-14);
  EXPECT_NEAR(norm(centre(screw) - centre(line)), r - 0.5, 1e-14);
}

TEST(Se3Interpolation, NearHalfTurnIsSmoothAndTurnsAtConstantRate) {
  std::mt19937_64 rng(14);
  for (int i = 0; i < 100; ++i) {
    const SE3 a = random_pose(rng);
    const Vec3 axis = random_unit(rng);
    const double epsilon = std::pow(10.0, -12 + 9 * double(i) / 99);  // 1e-12 .. 1e-3 short of pi
    const double theta = kPi - epsilon;
    const SE3 b = a * SE3::from_rt(theta * axis, {0.2, 0.1, -0.3});
    for (const PoseInterpolation method : kMethods) {
      for (const double s : {0.1, 0.5, 0.9, 1.1}) {
        const SE3 m = interpolate_camera_pose(a, b, s, method);
        EXPECT_LT(rotation_orthonormality_error(m.rotation()), 1e-14);
        // Constant rate about the same axis: the angle from a is s theta (beyond pi it wraps).
        const double expected = s <= 1 ? s * theta : 2 * kPi - s * theta;
        EXPECT_NEAR(angle_between(m, a), expected, 1e-9) << "epsilon " << epsilon << " s " << s;
        // ... about the axis of the relative rotation (not a neighbouring one): the relative
        // rotation to b is the rest of the turn.
        EXPECT_NEAR(angle_between(m, b), std::abs(1 - s) * theta, 1e-9);
      }
    }
  }
}

TEST(Se3Interpolation, TinyMotionsKeepTheirRelativePrecision) {
  // 1e-10 rad and 1e-10 m between the poses: the halfway pose is half of each, to relative 1e-5.
  const SE3 a = SE3::from_rt({0.4, -1.2, 0.7}, {0.1, 0.2, 0.5});
  const Vec3 w = 1e-10 * normalized(Vec3{1, 2, 3});
  const SE3 b = (a.inverse() * SE3::from_rt(w, {0, 0, 0}) * SE3(identity3(), {1e-10, 0, 0})).inverse();
  for (const PoseInterpolation method : kMethods) {
    const SE3 m = interpolate_camera_pose(a, b, 0.5, method);
    EXPECT_NEAR(angle_between(m, a), 0.5e-10, 1e-15);
    EXPECT_NEAR(angle_between(m, b), 0.5e-10, 1e-15);
    EXPECT_NEAR(centre_distance(m, a), 0.5 * centre_distance(a, b), 1e-15);
    EXPECT_NEAR(centre_distance(m, b), 0.5 * centre_distance(a, b), 1e-15);
  }
  // No motion at all: every s gives the pose back.
  for (const PoseInterpolation method : kMethods)
    for (const double s : {-3.0, 0.5, 7.0}) {
      const SE3 m = interpolate_camera_pose(a, a, s, method);
      EXPECT_LT(angle_between(m, a), 1e-15);
      EXPECT_LT(norm(m.translation() - a.translation()), 1e-15);
    }
}

TEST(Se3Interpolation, HugeMotionsStayFiniteAndOnTheLine) {
  // 1000 km apart, nearly a half turn, extrapolated three intervals ahead.
  const SE3 a = SE3::from_rt({0, 0, 0.1}, {1e6, -2e6, 3e5});
  const SE3 b = (a.inverse() * SE3::from_rt({0, 3.1, 0}, {1e6, 0, 0})).inverse();
  for (const double s : {0.5, 3.0, -2.0}) {
    const SE3 m = interpolate_camera_pose(a, b, s, PoseInterpolation::CentreLine);
    EXPECT_LT(rotation_orthonormality_error(m.rotation()), 1e-14);
    const Vec3 expected = (1 - s) * centre(a) + s * centre(b);
    EXPECT_LT(norm(centre(m) - expected), 1e-9 * norm(expected));  // relative rounding of 1e6 m values
    const SE3 screw = interpolate_camera_pose(a, b, s, PoseInterpolation::Screw);
    EXPECT_LT(rotation_orthonormality_error(screw.rotation()), 1e-14);
    EXPECT_TRUE(std::isfinite(screw.translation()[0]) && std::isfinite(screw.translation()[1]) &&
                std::isfinite(screw.translation()[2]));
    EXPECT_LT(angle_between(m, screw), 1e-12);  // same rotation path
  }
}

TEST(Se3Interpolation, TimeFractionIsExactForLargeClockValues) {
  const int64_t a = 9'000'000'000'000'000'000;  // about 285 years of CLOCK_MONOTONIC
  EXPECT_EQ(time_fraction(a, a + 33'333'333, a + 33'333'333), 1.0);
  EXPECT_EQ(time_fraction(a, a + 40'000'000, a + 10'000'000), 0.25);
  EXPECT_EQ(time_fraction(a, a + 40'000'000, a - 40'000'000), -1.0);
}

}  // namespace
}  // namespace arpipe
