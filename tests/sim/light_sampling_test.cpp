// Direction sampling against its analytic moments and bounds.
#include "capture/sim/light_sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "capture/sim/sample_rng.h"

namespace arpipe::sim {
namespace {

constexpr double kPi = std::numbers::pi;

std::vector<Vec3> test_normals() {
  std::vector<Vec3> normals{{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {1e-9, 0, -1}, {0, 1e-12, 1}};
  SampleRng rng(3, 4);
  for (int i = 0; i < 50; ++i) {
    const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform();
    const double r = std::sqrt(1 - z * z);
    normals.push_back({r * std::cos(phi), r * std::sin(phi), z});
  }
  for (Vec3& n : normals) n = normalized(n);
  return normals;
}

TEST(LightSampling, FrameIsOrthonormalAndRightHanded) {
  // 1e-12: the construction is a handful of products of unit-size numbers.
  for (const Vec3& n : test_normals()) {
    const Frame3 f = frame_around(n);
    EXPECT_NEAR(norm(f.t), 1, 1e-12);
    EXPECT_NEAR(norm(f.b), 1, 1e-12);
    EXPECT_NEAR(dot(f.t, f.b), 0, 1e-12);
    EXPECT_NEAR(dot(f.t, n), 0, 1e-12);
    EXPECT_NEAR(dot(f.b, n), 0, 1e-12);
    const Vec3 c = cross(f.t, f.b);
    for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(c[i], n[i], 1e-12);
    const Vec3 w = f.to_world(0, 0, 1);
    for (size_t i = 0; i < 3; ++i) EXPECT_EQ(w[i], n[i]);
  }
}

TEST(LightSampling, OneMinusCosKeepsTinyAnglesPrecise) {
  EXPECT_NEAR(one_minus_cos(1.0), 1 - std::cos(1.0), 1e-15);
  // The sun's half angle: 1 - cos(a) = a^2/2 - a^4/24 + a^6/720 (the next term is 1e-18
  // relative); the naive formula would lose 5 digits.
  const double a = 0.265 * kPi / 180, a2 = a * a;
  EXPECT_NEAR(one_minus_cos(a) / (a2 / 2 - a2 * a2 / 24 + a2 * a2 * a2 / 720), 1.0, 1e-14);
  EXPECT_NEAR(one_minus_cos(1e-9) / 5e-19, 1.0, 1e-12);
  EXPECT_EQ(one_minus_cos(0), 0);
  // Solid angles: a hemisphere is 2 pi, the whole sphere 4 pi.
  EXPECT_NEAR(cone_solid_angle(one_minus_cos(kPi / 2)), 2 * kPi, 1e-14);
  EXPECT_NEAR(cone_solid_angle(one_minus_cos(kPi)), 4 * kPi, 1e-14);
}

TEST(LightSampling, ConeSamplesAreUniformInsideTheCone) {
  SampleRng rng(1, 1);
  const int n = 40000;
  for (double half_angle : {0.3, 1.2, kPi / 2}) {
    const Vec3 axis = normalized(Vec3{0.3, -0.5, 0.8});
    const Frame3 frame = frame_around(axis);
    const double omc = one_minus_cos(half_angle);
    double sum_omc = 0, sum_t = 0, sum_b = 0;
    for (int i = 0; i < n; ++i) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 w = sample_cone(frame, omc, u1, u2);
      ASSERT_NEAR(norm(w), 1, 1e-12);
      ASSERT_LE(1 - dot(w, axis), omc * (1 + 1e-12) + 1e-15);
      sum_omc += 1 - dot(w, axis);
      sum_t += dot(w, frame.t);
      sum_b += dot(w, frame.b);
    }
    // Uniform in solid angle <=> 1 - cos(theta) uniform on [0, omc]: mean omc/2, sd omc/sqrt(12).
    // 5 standard errors of the mean.
    EXPECT_NEAR(sum_omc / n, omc / 2, 5 * omc / std::sqrt(12.0 * n)) << half_angle;
    // The azimuth is uniform: tangential components average to 0 (each has sd <= sin(a)/sqrt(2)).
    const double sd = std::sin(std::min(half_angle, kPi / 2)) / std::sqrt(2.0 * n);
    EXPECT_NEAR(sum_t / n, 0, 5 * sd);
    EXPECT_NEAR(sum_b / n, 0, 5 * sd);
  }
}

TEST(LightSampling, TinyConeStaysInsideTheSunDisc) {
  // The sun's disc (0.53 degrees): even the extreme u1 lands within the cone's chord length
  // 2 sin(a/2), to 1e-12 relative: no cancellation in the sampling.
  const double a = 0.265 * kPi / 180;
  const Vec3 axis = normalized(Vec3{0.2, 0.1, 1});
  const Frame3 frame = frame_around(axis);
  for (double u1 : {0.0, 0.5, 1 - 0x1p-32}) {
    const Vec3 w = sample_cone(frame, one_minus_cos(a), u1, 0.3);
    const double chord = norm(w - axis);
    EXPECT_LE(chord, 2 * std::sin(a / 2) * (1 + 1e-12));
    // Angle = acos(1 - u1 * omc) exactly: chord = 2 sin(theta/2) = sqrt(2 u1 omc).
    EXPECT_NEAR(chord, std::sqrt(2 * u1 * one_minus_cos(a)), 1e-12 * a);
  }
}

TEST(LightSampling, CosineHemisphereHasCosineDensity) {
  SampleRng rng(5, 9);
  const Vec3 n = normalized(Vec3{-0.2, 0.7, 0.3});
  const Frame3 frame = frame_around(n);
  const int count = 40000;
  double sum_cos = 0, sum_cos2 = 0, sum_t = 0;
  for (int i = 0; i < count; ++i) {
    const double u1 = rng.uniform(), u2 = rng.uniform();
    const Vec3 w = sample_cosine_hemisphere(frame, u1, u2);
    ASSERT_NEAR(norm(w), 1, 1e-12);
    ASSERT_GE(dot(w, n), 0);
    sum_cos += dot(w, n);
    sum_cos2 += dot(w, n) * dot(w, n);
    sum_t += dot(w, frame.t);
  }
  // With density cos/pi: E[cos] = 2/3 (sd 0.236), E[cos^2] = 1/2 (sd 0.289), E[t] = 0 (sd 0.5).
  // Tolerances: 5 standard errors.
  EXPECT_NEAR(sum_cos / count, 2.0 / 3.0, 5 * 0.236 / std::sqrt(count));
  EXPECT_NEAR(sum_cos2 / count, 0.5, 5 * 0.289 / std::sqrt(count));
  EXPECT_NEAR(sum_t / count, 0.0, 5 * 0.5 / std::sqrt(count));
}

TEST(LightSampling, SphereConeMatchesTheTangentAngle) {
  const Vec3 centre{1, 2, 3};
  const SphereCone cone = sphere_cone(Vec3{1, 2, 3 - 0.5}, centre, 0.1);
  ASSERT_TRUE(cone.outside);
  EXPECT_NEAR(cone.distance, 0.5, 1e-15);
  EXPECT_NEAR(cone.axis[2], 1, 1e-15);
  // sin(alpha) = r / d = 0.2.
  EXPECT_NEAR(cone.one_minus_cos, 1 - std::sqrt(1 - 0.04), 1e-15);
  // A tiny far sphere: 1 - cos = r^2 / (2 d^2) (1 + r^2/(4 d^2)), kept to full relative precision.
  const SphereCone far = sphere_cone(Vec3{0, 0, 0}, Vec3{0, 0, 1}, 1e-6);
  EXPECT_NEAR(far.one_minus_cos / 5e-13, 1.0, 1e-12);
  // Inside or on the sphere there is no cone.
  EXPECT_FALSE(sphere_cone(Vec3{1, 2, 3.05}, centre, 0.1).outside);
  EXPECT_FALSE(sphere_cone(Vec3{0, 0.5, 0}, Vec3{0, 0, 0}, 0.5).outside);
}

}  // namespace
}  // namespace arpipe::sim
