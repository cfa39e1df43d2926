// SE(3) tests: identities, analytic cases, angles near 0 and pi, and seeded random property checks,
// with OpenCV's Rodrigues as an independent implementation of the rotation-vector maps.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/se3.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

// Rotation about a coordinate axis, written out from the textbook formula.
Mat3 rot_z(double a) { return {{{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}}}; }
Mat3 rot_x(double a) { return {{{1, 0, 0}, {0, std::cos(a), -std::sin(a)}, {0, std::sin(a), std::cos(a)}}}; }

double max_abs_diff(const Mat3& a, const Mat3& b) {
  double d = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d = std::max(d, std::abs(a[i][j] - b[i][j]));
  return d;
}
double max_abs_diff(const Vec3& a, const Vec3& b) {
  return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}
double max_abs_diff(const SE3& a, const SE3& b) {
  return std::max(max_abs_diff(a.rotation(), b.rotation()), max_abs_diff(a.translation(), b.translation()));
}
double determinant(const Mat3& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Random poses whose angles cover (0, pi] with extra weight near both ends, where the maps are delicate.
class PoseGenerator {
 public:
  explicit PoseGenerator(uint64_t seed) : rng_(seed) {}
  Vec3 unit() {
    std::normal_distribution<double> n(0, 1);
    return normalized(Vec3{n(rng_), n(rng_), n(rng_)});
  }
  double angle() {
    std::uniform_real_distribution<double> u(0, 1);
    const double pick = u(rng_);
    if (pick < 0.15) return std::pow(10.0, -12 + 11 * u(rng_));        // 1e-12 .. 0.1
    if (pick < 0.30) return kPi - std::pow(10.0, -12 + 11 * u(rng_));  // pi - (1e-12 .. 0.1)
    return kPi * u(rng_);
  }
  SE3 pose() {
    std::uniform_real_distribution<double> t(-5, 5);
    return SE3::from_rt(angle() * unit(), {t(rng_), t(rng_), t(rng_)});
  }

 private:
  std::mt19937_64 rng_;
};

TEST(Se3, IdentityAndPointTransform) {
  const SE3 identity;
  EXPECT_EQ(max_abs_diff(identity.rotation(), identity3()), 0.0);
  const Vec3 p{1.5, -2, 3};
  EXPECT_EQ(max_abs_diff(identity * p, p), 0.0);
  // (R, t) maps p to R p + t: a quarter turn about z takes x to y.
  const SE3 T(rot_z(kPi / 2), {1, 2, 3});
  const Vec3 q = T * Vec3{1, 0, 0};
  EXPECT_NEAR(q[0], 1.0, 1e-15);
  EXPECT_NEAR(q[1], 3.0, 1e-15);
  EXPECT_NEAR(q[2], 3.0, 1e-15);
}

TEST(Se3, RotationFromVectorMatchesAxisAngleFormula) {
  // 1e-15: a handful of roundings of values of order 1.
  for (const double a : {1e-7, 0.3, 1.0, 2.5, kPi - 1e-6, kPi}) {
    EXPECT_LT(max_abs_diff(rotation_from_vector({0, 0, a}), rot_z(a)), 1e-15) << a;
    EXPECT_LT(max_abs_diff(rotation_from_vector({a, 0, 0}), rot_x(a)), 1e-15) << a;
  }
}

TEST(Se3, VectorFromRotationMatchesAnalyticAngle) {
  // Near zero the result is a tiny vector: its relative error is what matters (1e-12 allows a few
  // thousand ulps, far tighter than the 1e-8 the trace-only formula would reach at 1e-8 rad).
  for (const double a : {1e-14, 1e-10, 1e-8, 1e-5, 9.99e-4, 1.001e-3, 0.5, 3.0}) {
    const Vec3 r = vector_from_rotation(rot_z(a));
    EXPECT_NEAR(r[2], a, 1e-12 * a) << a;
    EXPECT_EQ(r[0], 0.0);
    EXPECT_EQ(r[1], 0.0);
  }
  EXPECT_EQ(norm(vector_from_rotation(identity3())), 0.0);
}

TEST(Se3, NearZeroAngleRoundTripKeepsRelativePrecision) {
  PoseGenerator gen(11);
  for (int i = 0; i < 200; ++i) {
    const double angle = std::pow(10.0, -15 + 12 * (i / 200.0));  // 1e-15 .. 1e-3
    const Vec3 r = angle * gen.unit();
    const Vec3 back = vector_from_rotation(rotation_from_vector(r));
    // Relative 1e-12: the off-diagonal terms carry the vector at full relative precision.
    EXPECT_LT(norm(back - r), 1e-12 * angle) << angle;
  }
}

TEST(Se3, NearPiAngleRoundTrip) {
  PoseGenerator gen(12);
  for (int i = 0; i < 200; ++i) {
    const Vec3 axis = gen.unit();
    const double angle = kPi - std::pow(10.0, -14 + 13 * (i / 200.0));  // pi - (1e-14 .. 0.1)
    const Vec3 r = angle * axis;
    const Vec3 back = vector_from_rotation(rotation_from_vector(r));
    // 1e-12 absolute on a vector of length ~3: Shepperd's branch keeps the axis exact near pi
    // (the trace formula alone would lose half the digits, ~1e-8).
    EXPECT_LT(norm(back - r), 1e-12) << "pi - " << kPi - angle;
  }
}

TEST(Se3, ExactlyPiGivesAngleOfPiAndTheSameRotation) {
  PoseGenerator gen(13);
  for (int i = 0; i < 100; ++i) {
    const Vec3 a = gen.unit();
    // R = 2 a a^T - I is a half turn about a; the vector is pi * a or -pi * a (same rotation).
    Mat3 R{};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R[r][c] = 2 * a[r] * a[c] - (r == c ? 1 : 0);
    const Vec3 v = vector_from_rotation(R);
    EXPECT_NEAR(norm(v), kPi, 1e-12);
    EXPECT_NEAR(std::abs(dot(normalized(v), a)), 1.0, 1e-12);
    EXPECT_LT(max_abs_diff(rotation_from_vector(v), R), 1e-14);
  }
}

TEST(Se3, RodriguesAgreesWithOpenCv) {
  // OpenCV's cv::Rodrigues is an independent implementation; both are exact formulas, so they
  // agree to rounding (1e-14). OpenCV's inverse is unreliable within ~1e-5 of pi, so that
  // direction is checked away from pi.
  PoseGenerator gen(14);
  for (int i = 0; i < 500; ++i) {
    const double angle = kPi * (i + 0.5) / 500.0;
    const Vec3 r = angle * gen.unit();
    cv::Mat R_cv;
    cv::Rodrigues(cv::Vec3d(r[0], r[1], r[2]), R_cv);
    const Mat3 R = rotation_from_vector(r);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) EXPECT_NEAR(R[a][b], R_cv.at<double>(a, b), 1e-14);
    if (angle < kPi - 1e-3) {
      cv::Vec3d r_cv;
      cv::Rodrigues(R_cv, r_cv);
      EXPECT_LT(max_abs_diff(vector_from_rotation(R), Vec3{r_cv[0], r_cv[1], r_cv[2]}), 1e-12) << angle;
    }
  }
}

TEST(Se3, ExpOfLogAndLogOfExpAreIdentities) {
  PoseGenerator gen(21);
  for (int i = 0; i < 1000; ++i) {
    const SE3 T = gen.pose();
    // 1e-12: translations are up to ~9 m and V^-1 near pi amplifies rounding by ~1/sin.
    EXPECT_LT(max_abs_diff(SE3::exp(T.log()), T), 1e-12) << i;
  }
  // A twist with |omega| < pi is the unique log of its exponential.
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 1000; ++i) {
    Vec6 xi{3 * u(rng), 3 * u(rng), 3 * u(rng), u(rng), u(rng), u(rng)};
    const Vec6 back = SE3::exp(xi).log();
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(back[k], xi[k], 1e-12);
  }
}

TEST(Se3, ExpMatchesClosedFormScrewMotion) {
  // A screw along z: rotating by a about z while advancing along z moves no point off the axis
  // except by rotation; exp((0,0,h, 0,0,a)) = (Rz(a), (0,0,h)). And a pure translation twist is
  // a translation.
  const SE3 screw = SE3::exp({0, 0, 2.0, 0, 0, 0.7});
  EXPECT_LT(max_abs_diff(screw.rotation(), rot_z(0.7)), 1e-15);
  EXPECT_LT(max_abs_diff(screw.translation(), Vec3{0, 0, 2.0}), 1e-15);
  // Rotation a about z with rho = (v, 0, 0): t = V rho = (sin a, 1 - cos a, 0) * v / a.
  const double a = 1.3, v = 0.8;
  const SE3 arc = SE3::exp({v, 0, 0, 0, 0, a});
  EXPECT_LT(max_abs_diff(arc.translation(), Vec3{std::sin(a) * v / a, (1 - std::cos(a)) * v / a, 0}), 1e-15);
  const SE3 shift = SE3::exp({1, 2, 3, 0, 0, 0});
  EXPECT_EQ(max_abs_diff(shift.translation(), Vec3{1, 2, 3}), 0.0);
}

TEST(Se3, InverseAndCompose) {
  PoseGenerator gen(31);
  for (int i = 0; i < 1000; ++i) {
    const SE3 A = gen.pose(), B = gen.pose(), C = gen.pose();
    // Products of orthonormal matrices with translations of a few metres: rounding ~1e-15.
    EXPECT_LT(max_abs_diff(A * A.inverse(), SE3()), 1e-14);
    EXPECT_LT(max_abs_diff(A.inverse() * A, SE3()), 1e-14);
    EXPECT_LT(max_abs_diff((A * B) * C, A * (B * C)), 1e-13);
    const Vec3 p{0.3, -1.2, 2.5};
    EXPECT_LT(max_abs_diff((A * B) * p, A * (B * p)), 1e-13);
    EXPECT_LT(max_abs_diff(A.inverse() * (A * p), p), 1e-13);
    EXPECT_EQ(max_abs_diff(A.rotate(p), mat_mul(A.rotation(), p)), 0.0);
    // Every rotation the class makes is orthonormal with determinant +1.
    const Mat3 RtR = mat_mul(transpose((A * B).rotation()), (A * B).rotation());
    EXPECT_LT(max_abs_diff(RtR, identity3()), 1e-14);
    EXPECT_NEAR(determinant((A * B).rotation()), 1.0, 1e-14);
  }
}

TEST(Se3, InterpolateEndpointsAndAnalyticMidpoint) {
  // From the identity to a quarter turn about z with t = (2, 0, 0): halfway is an eighth turn
  // and t = (1, 0, 0); a quarter of the way is a sixteenth turn and t = (0.5, 0, 0).
  const SE3 a;
  const SE3 b(rot_z(kPi / 2), {2, 0, 0});
  EXPECT_LT(max_abs_diff(a.interpolate(b, 0.0), a), 1e-15);
  EXPECT_LT(max_abs_diff(a.interpolate(b, 1.0), b), 1e-15);
  EXPECT_LT(max_abs_diff(a.interpolate(b, 0.5), SE3(rot_z(kPi / 4), {1, 0, 0})), 1e-15);
  EXPECT_LT(max_abs_diff(a.interpolate(b, 0.25), SE3(rot_z(kPi / 8), {0.5, 0, 0})), 1e-15);
  // Extrapolation continues at the same rate.
  EXPECT_LT(max_abs_diff(a.interpolate(b, 2.0), SE3(rot_z(kPi), {4, 0, 0})), 1e-15);

  // From a tilted start: the relative rotation about the start's own z is split evenly.
  const SE3 c(rot_x(0.6), {1, 1, 1});
  const SE3 d(mat_mul(rot_x(0.6), rot_z(1.2)), {3, -1, 5});
  EXPECT_LT(max_abs_diff(c.interpolate(d, 0.5), SE3(mat_mul(rot_x(0.6), rot_z(0.6)), {2, 0, 3})), 1e-15);
}

TEST(Se3, InterpolateHasConstantAngularRateIncludingNearPi) {
  PoseGenerator gen(41);
  for (int i = 0; i < 300; ++i) {
    const SE3 a = gen.pose(), b = gen.pose();
    const double total = rotation_angle_between(a, b);
    for (const double s : {0.0, 0.2, 0.5, 0.9, 1.0}) {
      const SE3 m = a.interpolate(b, s);
      // Geodesic: angle from a is s * total and angle to b is (1 - s) * total. 1e-11 covers
      // totals within 1e-12 of pi where the direction of the relative axis is ill-posed.
      EXPECT_NEAR(rotation_angle_between(a, m), s * total, 1e-11);
      EXPECT_NEAR(rotation_angle_between(m, b), (1 - s) * total, 1e-11);
    }
    EXPECT_LT(max_abs_diff(a.interpolate(b, 1.0), b), 1e-12);
  }
  // Antipodal: a half turn; the midpoint is a quarter turn from both ends.
  const SE3 half_turn(rot_z(kPi), {0, 0, 0});
  const SE3 mid = SE3().interpolate(half_turn, 0.5);
  EXPECT_NEAR(rotation_angle_between(SE3(), mid), kPi / 2, 1e-14);
  EXPECT_NEAR(rotation_angle_between(mid, half_turn), kPi / 2, 1e-14);
}

TEST(Se3, RotationAngleBetween) {
  const SE3 a(rot_x(0.4), {0, 0, 0});
  const SE3 b(mat_mul(rot_x(0.4), rot_z(0.25)), {5, 5, 5});
  EXPECT_NEAR(rotation_angle_between(a, b), 0.25, 1e-15);
  EXPECT_NEAR(rotation_angle_between(b, a), 0.25, 1e-15);
  EXPECT_NEAR(rotation_angle_between(a, SE3(mat_mul(rot_x(0.4), rot_z(1e-9)), {})), 1e-9, 1e-20);
}

TEST(Se3, NormalizedRepairsDriftedRotation) {
  PoseGenerator gen(51);
  for (int i = 0; i < 100; ++i) {
    const SE3 T = gen.pose();
    // Perturb the rotation by 1e-9 per entry (what a long chain of products can accumulate).
    Mat3 drifted = T.rotation();
    std::mt19937_64 rng(1000 + i);
    std::uniform_real_distribution<double> u(-1e-9, 1e-9);
    for (auto& row : drifted)
      for (double& x : row) x += u(rng);
    const SE3 repaired = SE3(drifted, T.translation()).normalized();
    const Mat3& R = repaired.rotation();
    EXPECT_LT(max_abs_diff(mat_mul(transpose(R), R), identity3()), 1e-15);
    EXPECT_NEAR(determinant(R), 1.0, 1e-15);
    // The polar factor is the nearest rotation, so it moves no further than the drift did.
    EXPECT_LT(max_abs_diff(R, T.rotation()), 3e-9);
    EXPECT_EQ(max_abs_diff(repaired.translation(), T.translation()), 0.0);
  }
  // An exact rotation is left unchanged (to rounding).
  const SE3 exact(rot_z(0.3), {1, 2, 3});
  EXPECT_LT(max_abs_diff(exact.normalized(), exact), 1e-16);
}

TEST(Se3, FromRtMatchesRotationFromVector) {
  const SE3 T = SE3::from_rt({0.1, -0.2, 0.3}, {4, 5, 6});
  EXPECT_EQ(max_abs_diff(T.rotation(), rotation_from_vector({0.1, -0.2, 0.3})), 0.0);
  EXPECT_EQ(max_abs_diff(T.translation(), Vec3{4, 5, 6}), 0.0);
  EXPECT_LT(max_abs_diff(T.rotation_vector(), Vec3{0.1, -0.2, 0.3}), 1e-16);
}

}  // namespace
}  // namespace arpipe
