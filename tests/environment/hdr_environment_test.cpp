// HdrEnvironment against an analytic environment f(d) = 1 + d.x + 2 d.z^2 (world frame) sampled
// at texel centres, for all four layouts under a non-trivial yaw: radiance() reproduces f within
// a bound derived from the local texel size, converges at second order, never reads a blank
// texel; for_each_texel covers 4 pi and integrates f to 4 pi (1 + 2/3). Plus the placement
// (default_world_from_probe), the scale, loading and the constructor's checks.
#include "core/environment/hdr_environment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

using hdr_test::angle_between;
using hdr_test::random_direction;

constexpr double kPi = std::numbers::pi;
constexpr double kBlank = 1e6;  // written into texels outside the layout: reading one shows at once
constexpr std::array<EnvironmentLayout, 4> kLayouts = {EnvironmentLayout::AngularMap, EnvironmentLayout::MirrorBall,
                                                 EnvironmentLayout::Equirectangular, EnvironmentLayout::CubeCross};

double f(const Vec3& d) { return 1 + d[0] + 2 * d[2] * d[2]; }
// |grad f| on the sphere <= |grad x| + |grad 2 z^2| <= 1 + 4 |z| sqrt(1 - z^2) <= 1 + 2 = 3.
constexpr double kGradientBound = 3;

std::array<int, 2> size_of(EnvironmentLayout layout, int n) {
  switch (layout) {
    case EnvironmentLayout::Equirectangular: return {2 * n, n};
    case EnvironmentLayout::CubeCross: return {3 * n, 4 * n};
    default: return {n, n};
  }
}

HdrEnvironment analytic_environment(EnvironmentLayout layout, int n, const Mat3& R) {
  const auto [w, h] = size_of(layout, n);
  HdrImage image{w, h, std::vector<float>(3 * static_cast<size_t>(w) * h, static_cast<float>(kBlank))};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (const auto d = environment_pixel_direction(layout, w, h, x, y)) {
        const float value = static_cast<float>(f(mat_mul(R, *d)));
        for (int c = 0; c < 3; ++c) image.rgb[3 * (static_cast<size_t>(y) * w + x) + c] = value;
      }
  return HdrEnvironment(std::move(image), layout, R, 1.0, std::string(environment_layout_name(layout)) + "-analytic");
}

// The largest angle between d_probe and the directions of the points a lookup at pixel p may read
// (bilinear taps within p + [-1, 1]^2; a disk tap outside the disk is replaced by a valid texel
// within about 1.5 px, so p + [-2.5, 2.5]^2 there), brought into the layout's valid region the
// way the lookup does (equirect wraps columns and clamps rows, cube taps stay on their face).
double neighbourhood_angle(const HdrEnvironment& env, const Vec3& d_probe) {
  const int w = env.width(), h = env.height();
  const Vec2 p = environment_direction_pixel(env.layout(), w, h, d_probe);
  const bool disk = env.layout() == EnvironmentLayout::AngularMap || env.layout() == EnvironmentLayout::MirrorBall;
  const double reach = disk ? 2.5 : 1.0;
  double worst = 0;
  for (double dy = -reach; dy <= reach; dy += 0.25)
    for (double dx = -reach; dx <= reach; dx += 0.25) {
      double qx = p[0] + dx, qy = p[1] + dy;
      if (env.layout() == EnvironmentLayout::Equirectangular) {
        qx = std::fmod(qx + 0.5 + w, w) - 0.5;
        qy = std::clamp(qy, -0.5, h - 0.5);
      } else if (env.layout() == EnvironmentLayout::CubeCross) {
        const int face = w / 3;
        const std::array<int, 2> cell = cube_cross_face_cell(d_probe);
        qx = std::clamp(qx, cell[0] * face - 0.5, (cell[0] + 1) * face - 0.5);
        qy = std::clamp(qy, cell[1] * face - 0.5, (cell[1] + 1) * face - 0.5);
        if (qx == (cell[0] + 1) * face - 0.5) qx -= 1e-9;  // stay on this face's side of the border
        if (qy == (cell[1] + 1) * face - 0.5) qy -= 1e-9;
      }
      const auto q = environment_pixel_direction(env.layout(), w, h, qx, qy);
      if (q) worst = std::max(worst, angle_between(d_probe, *q));
    }
  return worst;
}

struct LookupErrors {
  double mean = 0, max = 0;
};

LookupErrors lookup_errors(EnvironmentLayout layout, int n, const Mat3& R, int samples, bool check_bound) {
  const HdrEnvironment env = analytic_environment(layout, n, R);
  std::mt19937_64 rng(123);
  LookupErrors errors;
  for (int i = 0; i < samples; ++i) {
    const Vec3 d = random_direction(rng);
    const Vec3 value = env.radiance(d);
    const double error = std::abs(value[0] - f(d));
    EXPECT_LT(value[0], 100) << "a blank texel was read at " << d[0] << "," << d[1] << "," << d[2];
    if (check_bound) {
      // Bilinear weights are convex, so the result lies between the values at the read texels:
      // |error| <= max |f(tap) - f(d)| <= |grad f| * angle, plus float storage (2^-24 * 4).
      const double bound = kGradientBound * neighbourhood_angle(env, mat_mul(transpose(R), d)) + 1e-6;
      EXPECT_LE(error, bound) << environment_layout_name(layout) << " at " << d[0] << "," << d[1] << "," << d[2];
    }
    errors.mean += error / samples;
    errors.max = std::max(errors.max, error);
  }
  return errors;
}

TEST(HdrEnvironment, DefaultPlacement) {
  const Mat3 R = default_world_from_probe(0);
  const auto expect_maps = [](const Mat3& m, const Vec3& probe, const Vec3& world) {
    const Vec3 got = mat_mul(m, probe);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], world[k], 1e-15);
  };
  expect_maps(R, {0, 1, 0}, {0, 0, 1});   // up -> world +z
  expect_maps(R, {0, 0, -1}, {0, 1, 0});  // forward -> world +y
  expect_maps(R, {1, 0, 0}, {1, 0, 0});   // right -> world +x
  // Yaw 90 degrees, counter-clockwise seen from above (+z): forward +y turns to -x, right to +y.
  const Mat3 turned = default_world_from_probe(kPi / 2);
  expect_maps(turned, {0, 0, -1}, {-1, 0, 0});
  expect_maps(turned, {1, 0, 0}, {0, 1, 0});
  expect_maps(turned, {0, 1, 0}, {0, 0, 1});
}

TEST(HdrEnvironment, RadianceReproducesAnAnalyticEnvironment) {
  const Mat3 R = default_world_from_probe(0.7);
  for (EnvironmentLayout layout : kLayouts) {
    const int n = layout == EnvironmentLayout::CubeCross ? 32 : 64;
    const LookupErrors errors = lookup_errors(layout, n, R, 3000, true);
    std::printf("%s n=%d: lookup error mean %.3g max %.3g\n", std::string(environment_layout_name(layout)).c_str(), n,
                errors.mean, errors.max);
  }
}

TEST(HdrEnvironment, LookupConvergesAtSecondOrder) {
  // Bilinear interpolation of a smooth function errs by O(h^2): doubling the resolution divides
  // the mean error by ~4. Require 3 (the disk layouts' rims, where the maps are not smooth,
  // hold a small share of the directions).
  const Mat3 R = default_world_from_probe(0.7);
  for (EnvironmentLayout layout : kLayouts) {
    const int n = layout == EnvironmentLayout::CubeCross ? 24 : 48;
    const double coarse = lookup_errors(layout, n, R, 4000, false).mean;
    const double fine = lookup_errors(layout, 2 * n, R, 4000, false).mean;
    std::printf("%s: mean lookup error %.3g at n=%d, %.3g at n=%d (ratio %.2f)\n",
                std::string(environment_layout_name(layout)).c_str(), coarse, n, fine, 2 * n, coarse / fine);
    EXPECT_GT(coarse / fine, 3) << environment_layout_name(layout);
  }
}

TEST(HdrEnvironment, ForEachTexelCoversTheSphereAndIntegratesF) {
  // Exact per-texel solid angles: the sum is 4 pi to the layout's solid-angle accuracy (1e-9).
  // The integral of f is 4 pi (1 + 0 + 2/3) (the mean of z^2 over the sphere is 1/3). The texel
  // sum errs by at most sum_t Omega_t |grad f| alpha_t, alpha_t the largest angle from the texel's
  // reported direction to a point of its footprint (sampled on a 9 x 9 grid); that first-order
  // bound is checked, and the convergence order: second order (error ratio > 3 when the resolution
  // doubles) for the smooth maps. The mirror ball's rim is singular (the last texels before the rim
  // hold O(h) of solid angle over directions spread O(sqrt h) around their centres, which cancels
  // around the ring only to O(h^1.5)), and its error alternates in size from one doubling to the
  // next, so it is checked over two doublings: order 1.5 gives a ratio of 8, require > 6.
  const Mat3 R = default_world_from_probe(0.7);
  const double expected = 4 * kPi * (1 + 2.0 / 3.0);
  for (EnvironmentLayout layout : kLayouts) {
    const bool mirror = layout == EnvironmentLayout::MirrorBall;
    std::array<double, 2> error{};
    for (int level = 0; level < 2; ++level) {
      const int n = (layout == EnvironmentLayout::CubeCross ? 16 : 32) << (mirror ? 2 * level : level);
      const HdrEnvironment env = analytic_environment(layout, n, R);
      double solid_angle = 0, integral = 0;
      int texels = 0;
      env.for_each_texel([&](const Vec3& d, const Vec3& radiance, double omega) {
        EXPECT_NEAR(norm(d), 1, 1e-12);
        EXPECT_LT(radiance[0], 100) << "a blank texel was reported";
        solid_angle += omega;
        integral += radiance[0] * omega;
        ++texels;
      });
      EXPECT_NEAR(solid_angle, 4 * kPi, 1e-9 * 4 * kPi) << environment_layout_name(layout);
      double bound = 0;
      const int w = env.width(), h = env.height();
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const double omega = environment_texel_solid_angle(layout, w, h, x, y);
          if (omega <= 0) continue;
          const auto centre = environment_pixel_direction(layout, w, h, x, y);
          const Vec3 reported = centre ? *centre : Vec3{0, 0, layout == EnvironmentLayout::AngularMap ? 1.0 : -1.0};
          double alpha = 0;
          for (int j = 0; j <= 8; ++j)
            for (int i = 0; i <= 8; ++i)
              if (const auto q = environment_pixel_direction(layout, w, h, x - 0.5 + i / 8.0, y - 0.5 + j / 8.0))
                alpha = std::max(alpha, angle_between(reported, *q));
          bound += omega * kGradientBound * alpha;
        }
      error[level] = std::abs(integral - expected);
      std::printf("%s n=%d: %d texels, solid angle - 4 pi = %.3g, integral error %.3g (first-order bound %.3g)\n",
                  std::string(environment_layout_name(layout)).c_str(), n, texels, solid_angle - 4 * kPi, integral - expected,
                  bound);
      EXPECT_LE(error[level], bound) << environment_layout_name(layout);
    }
    EXPECT_GT(error[0] / error[1], mirror ? 6 : 3) << environment_layout_name(layout);
  }
}

TEST(HdrEnvironment, ScaleMultipliesRadiance) {
  const Mat3 R = default_world_from_probe(0.3);
  const HdrEnvironment one = analytic_environment(EnvironmentLayout::Equirectangular, 16, R);
  const HdrEnvironment scaled(one.image(), one.layout(), R, 2.5, "scaled");
  std::mt19937_64 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Vec3 d = random_direction(rng);
    EXPECT_NEAR(scaled.radiance(d)[1], 2.5 * one.radiance(d)[1], 1e-12);
  }
  double a = 0, b = 0;
  one.for_each_texel([&](const Vec3&, const Vec3& radiance, double omega) { a += radiance[2] * omega; });
  scaled.for_each_texel([&](const Vec3&, const Vec3& radiance, double omega) { b += radiance[2] * omega; });
  EXPECT_NEAR(b, 2.5 * a, 1e-12 * b);
}

TEST(HdrEnvironment, LoadAndConstructorChecks) {
  const auto dir = hdr_test::scratch_dir();
  // An equirect probe bright straight up (rows 0-1 of 8), written as .hdr and loaded.
  HdrImage image{16, 8, std::vector<float>(16 * 8 * 3, 0.5f)};
  for (size_t i = 0; i < 16 * 2 * 3; ++i) image.rgb[i] = 8;
  write_radiance_hdr(dir / "sky.hdr", image);
  const HdrEnvironment env = HdrEnvironment::load(dir / "sky.hdr", EnvironmentLayout::Equirectangular, default_world_from_probe(1.0), 1.0);
  EXPECT_EQ(env.name(), (dir / "sky.hdr").string());
  EXPECT_EQ(env.width(), 16);
  EXPECT_EQ(env.height(), 8);
  EXPECT_EQ(env.layout(), EnvironmentLayout::Equirectangular);
  EXPECT_EQ(env.radiance({0, 0, 1})[0], 8);     // world up is probe up, whatever the yaw
  EXPECT_EQ(env.radiance({0, 0, -1})[0], 0.5);  // and down

  const auto message = [&](const std::function<void()>& make) { return hdr_test::asset_error_message(make); };
  EXPECT_NE(message([&] { HdrEnvironment::load(dir / "sky.hdr", EnvironmentLayout::AngularMap, identity3(), 1); })
                .find((dir / "sky.hdr").string() + ": layout \"angular\" needs a square image, but it is 16 x 8"),
            std::string::npos);
  HdrImage bad = image;
  bad.rgb[3 * (16 * 5 + 7)] = std::nanf("");
  EXPECT_NE(message([&] { HdrEnvironment(bad, EnvironmentLayout::Equirectangular, identity3(), 1, "bad.exr"); })
                .find("bad.exr: pixel (7, 5) channel R: NaN value"),
            std::string::npos);
  EXPECT_NE(message([&] { HdrEnvironment(image, EnvironmentLayout::Equirectangular, identity3(), -1, "neg"); }).find("neg: radiance scale -1"),
            std::string::npos);
  Mat3 not_rotation = identity3();
  not_rotation[2][2] = -1;  // a reflection
  EXPECT_NE(message([&] { HdrEnvironment(image, EnvironmentLayout::Equirectangular, not_rotation, 1, "mirror"); }).find("not a rotation"),
            std::string::npos);
  EXPECT_NE(message([&] { HdrEnvironment::load(dir / "missing.hdr", EnvironmentLayout::Equirectangular, identity3(), 1); })
                .find("missing.hdr: cannot open"),
            std::string::npos);
}

}  // namespace
}  // namespace arpipe
