// Affine2 and fit_affine: known random maps recovered from 3, 4 and 8 points, inverse and
// composition, least squares against known noise, the collinear and coincident fallbacks, huge
// coordinates, tiny motions and invalid input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "core/motion/affine_2d.h"

namespace arpipe {
namespace {

// A random well-conditioned map: linear part near a rotation-and-scale with some shear, and a
// translation of up to 200 px.
Affine2 random_affine(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi), scale(0.5, 2.0),
      shear(-0.3, 0.3), shift(-200.0, 200.0);
  const double th = angle(rng), sx = scale(rng), sy = scale(rng), k = shear(rng);
  // R(th) * [sx k; 0 sy]
  const double ct = std::cos(th), st = std::sin(th);
  return Affine2{{ct * sx, ct * k - st * sy, shift(rng), st * sx, st * k + ct * sy, shift(rng)}};
}

std::vector<Vec2> random_points(std::mt19937& rng, int count, double offset = 0) {
  std::uniform_real_distribution<double> x(0.0, 640.0), y(0.0, 480.0);
  std::vector<Vec2> points;
  for (int i = 0; i < count; ++i) points.push_back({offset + x(rng), offset + y(rng)});
  return points;
}

std::vector<Vec2> mapped(const Affine2& map, const std::vector<Vec2>& points) {
  std::vector<Vec2> out;
  for (const Vec2& p : points) out.push_back(map.apply(p));
  return out;
}

// Largest entry difference, the translation scaled down by `length` (px) so that all six compare
// as pixels at that distance from the origin.
double map_difference(const Affine2& a, const Affine2& b, double length = 1) {
  double worst = 0;
  for (int i = 0; i < 6; ++i) {
    const double scale = (i == 2 || i == 5) ? 1 / length : 1.0;
    worst = std::max(worst, std::abs(a.m[size_t(i)] - b.m[size_t(i)]) * scale);
  }
  return worst;
}

TEST(Affine2, InverseAndCompositionAreConsistent) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    const Affine2 map = random_affine(rng);
    const auto inverse = map.inverse();
    ASSERT_TRUE(inverse);
    // Entries are O(1) and the translation O(200): double rounding leaves ~1e-13; 1e-12 allows
    // for the condition number of the random linear part (singular values 0.5..2 with shear).
    EXPECT_LT(map_difference(*inverse * map, Affine2::identity(), 200), 1e-12);
    EXPECT_LT(map_difference(map * *inverse, Affine2::identity(), 200), 1e-12);
    // (a * b).apply(p) == a.apply(b.apply(p)), exactly up to rounding.
    const Affine2 other = random_affine(rng);
    const Vec2 p{123.25, -47.5};
    const Vec2 composed = (map * other).apply(p), chained = map.apply(other.apply(p));
    EXPECT_NEAR(composed[0], chained[0], 1e-10);
    EXPECT_NEAR(composed[1], chained[1], 1e-10);
  }
}

TEST(Affine2, SingularMapsHaveNoInverse) {
  EXPECT_FALSE((Affine2{{1, 2, 5, 2, 4, 7}}).inverse());  // rank 1
  EXPECT_FALSE((Affine2{{0, 0, 5, 0, 0, 7}}).inverse());  // rank 0
  EXPECT_FALSE((Affine2{{1, 0, 0, 0, 1e-13, 0}}).inverse());  // |det| below 1e-12 of the scale
  EXPECT_TRUE((Affine2{{1e-3, 0, 0, 0, 1e-3, 0}}).inverse());  // small but well conditioned
  const auto translation_inverse = Affine2::translation({3, -4}).inverse();
  ASSERT_TRUE(translation_inverse);
  EXPECT_EQ(translation_inverse->m, (Affine2::translation({-3, 4}).m));
}

TEST(FitAffine, RecoversRandomMapsFromThreeFourAndEightPoints) {
  std::mt19937 rng(42);
  for (int count : {3, 4, 8}) {
    for (int trial = 0; trial < 200; ++trial) {
      const Affine2 truth = random_affine(rng);
      const std::vector<Vec2> src = random_points(rng, count);
      const auto fit = fit_affine(src, mapped(truth, src));
      ASSERT_TRUE(fit);
      // Three random points in a 640x480 box can be nearly collinear; such a draw is not what
      // this test is about (the collinear case has its own tests).
      if (fit->kind != AffineFitKind::Full) continue;
      // Exact data: only rounding (1e-16 relative) amplified by the points' conditioning remains.
      // 1e-9 relative (of entries ~1, translation ~640 px) is the bound the brief asks for.
      EXPECT_LT(map_difference(fit->map, truth, 640), 1e-9) << count << " points, trial " << trial;
      EXPECT_LT(fit->rms_residual_px, 1e-9);
    }
  }
}

TEST(FitAffine, NoisyPointsGiveTheLeastSquaresResidual) {
  // 2000 pairs with isotropic Gaussian noise sigma on the destinations: with 6 parameters fitted to
  // 2N numbers, E[rms^2] = sigma^2 (2N - 6) / N. The chi-square over 3994 degrees of freedom has a
  // relative spread of sqrt(2/3994) = 2.2% (1.1% on the rms); 5% is 4.5 of those.
  std::mt19937 rng(3);
  const double sigma = 0.5;
  const int count = 2000;
  std::normal_distribution<double> noise(0.0, sigma);
  const Affine2 truth = random_affine(rng);
  const std::vector<Vec2> src = random_points(rng, count);
  std::vector<Vec2> dst = mapped(truth, src);
  for (Vec2& p : dst) p = {p[0] + noise(rng), p[1] + noise(rng)};
  const auto fit = fit_affine(src, dst);
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->kind, AffineFitKind::Full);
  const double expected_rms = sigma * std::sqrt((2.0 * count - 6) / count);
  EXPECT_NEAR(fit->rms_residual_px, expected_rms, 0.05 * expected_rms);
  // The linear part's standard error is sigma / sqrt(N var(x)) = 0.5 / sqrt(2000 * 480^2/12) = 8e-5
  // (the narrower axis); 1e-3 is over 10 of them. Across the box the map is then within ~0.1 px.
  for (const Vec2& p : {Vec2{0, 0}, Vec2{640, 480}, Vec2{320, 240}}) {
    EXPECT_LT(norm(fit->map.apply(p) - truth.apply(p)), 0.1);
  }
  for (int i : {0, 1, 3, 4}) EXPECT_NEAR(fit->map.m[size_t(i)], truth.m[size_t(i)], 1e-3);
  // Least squares: no other map has a smaller residual; a nudged one must be worse.
  auto rms_of = [&](const Affine2& map) {
    double sum = 0;
    for (size_t i = 0; i < src.size(); ++i) {
      const Vec2 r = dst[i] - map.apply(src[i]);
      sum += r[0] * r[0] + r[1] * r[1];
    }
    return std::sqrt(sum / double(src.size()));
  };
  EXPECT_NEAR(rms_of(fit->map), fit->rms_residual_px, 1e-9);
  for (size_t i = 0; i < 6; ++i) {
    Affine2 nudged = fit->map;
    nudged.m[i] += (i == 2 || i == 5) ? 0.01 : 1e-4;
    EXPECT_GT(rms_of(nudged), fit->rms_residual_px);
  }
}

// The similarity a collinear fit must return: rotation by `angle`, scale `s`, translation `t`.
Affine2 similarity(double angle, double s, const Vec2& t) {
  const double c = s * std::cos(angle), n = s * std::sin(angle);
  return Affine2{{c, -n, t[0], n, c, t[1]}};
}

TEST(FitAffine, CollinearPointsGiveTheSimilarityAlongTheLine) {
  // Points on a line through (100, 50) at 30 degrees, mapped by a known similarity: the fit must
  // be that similarity, off the line too. Exact data, so rounding only: 1e-9 of entries ~1.
  const double line = std::numbers::pi / 6;
  const Affine2 truth = similarity(0.4, 1.3, {20, -35});
  for (int count : {3, 8}) {
    std::vector<Vec2> src;
    for (int i = 0; i < count; ++i) {
      const double s = -150.0 + 45.0 * i;  // includes uneven spacing relative to the centre
      src.push_back({100 + s * std::cos(line), 50 + s * std::sin(line)});
    }
    const auto fit = fit_affine(src, mapped(truth, src));
    ASSERT_TRUE(fit);
    EXPECT_EQ(fit->kind, AffineFitKind::Similarity) << count;
    EXPECT_LT(map_difference(fit->map, truth, 640), 1e-9) << count;
    EXPECT_LT(fit->rms_residual_px, 1e-9);
  }
}

TEST(FitAffine, CollinearPointsUnderAGeneralMapMatchItAlongTheLine) {
  // A general affine map restricted to a line is still exact there; across the line the fit turns
  // and scales the perpendicular like the line (u -> w, u_perp -> R90 w).
  std::mt19937 rng(11);
  const Affine2 truth = random_affine(rng);
  const Vec2 origin{300, 200}, u{0.6, 0.8};
  std::vector<Vec2> src;
  for (int i = 0; i < 8; ++i) src.push_back({origin[0] + 20.0 * i * u[0], origin[1] + 20.0 * i * u[1]});
  const auto fit = fit_affine(src, mapped(truth, src));
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->kind, AffineFitKind::Similarity);
  for (double s : {-500.0, 0.0, 70.0, 1000.0}) {  // on the line, inside and far outside the points
    const Vec2 p{origin[0] + s * u[0], origin[1] + s * u[1]};
    EXPECT_LT(norm(fit->map.apply(p) - truth.apply(p)), 1e-9 * (1 + std::abs(s)));
  }
  const Vec2 w{truth.m[0] * u[0] + truth.m[1] * u[1], truth.m[3] * u[0] + truth.m[4] * u[1]};
  const Vec2 perp_image{fit->map.m[0] * -u[1] + fit->map.m[1] * u[0], fit->map.m[3] * -u[1] + fit->map.m[4] * u[0]};
  EXPECT_NEAR(perp_image[0], -w[1], 1e-12);
  EXPECT_NEAR(perp_image[1], w[0], 1e-12);
}

TEST(FitAffine, TwoPointsAreCollinear) {
  const std::vector<Vec2> src{{10, 10}, {20, 10}}, dst{{0, 0}, {0, 20}};  // turned 90 degrees, doubled
  const auto fit = fit_affine(src, dst);
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->kind, AffineFitKind::Similarity);
  EXPECT_LT(map_difference(fit->map, similarity(std::numbers::pi / 2, 2, {20, -20}), 20), 1e-12);
}

TEST(FitAffine, CoincidentPointsGiveTheMeanDisplacement) {
  const std::vector<Vec2> src(5, Vec2{100, 200});
  const std::vector<Vec2> dst{{101, 203}, {103, 201}, {102, 202}, {101, 202}, {103, 202}};  // mean shift (2, 2)
  const auto fit = fit_affine(src, dst);
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->kind, AffineFitKind::Translation);
  EXPECT_LT(map_difference(fit->map, Affine2::translation({2, 2})), 1e-12);
  // Residuals about the mean: (-1,1), (1,-1), (0,0), (-1,0), (1,0) -> sqrt(6/5).
  EXPECT_NEAR(fit->rms_residual_px, std::sqrt(6.0 / 5.0), 1e-12);

  const std::vector<Vec2> one_src{{5, 5}}, one_dst{{8, 1}};
  const auto single = fit_affine(one_src, one_dst);
  ASSERT_TRUE(single);
  EXPECT_EQ(single->kind, AffineFitKind::Translation);
  EXPECT_EQ(single->map.m, (Affine2::translation({3, -4}).m));
  EXPECT_EQ(single->rms_residual_px, 0);

  // Spread below 1e-12 px^2 (1e-7 px apart) still counts as one point.
  const std::vector<Vec2> close_src{{5, 5}, {5 + 1e-7, 5}, {5, 5 + 1e-7}}, close_dst{{6, 6}, {6, 6}, {6, 6}};
  const auto close = fit_affine(close_src, close_dst);
  ASSERT_TRUE(close);
  EXPECT_EQ(close->kind, AffineFitKind::Translation);
}

TEST(FitAffine, HugeCoordinatesStayAccurate) {
  // Points 1e6 px from the origin: their pixel values carry rounding of ulp(1e6) = 1.2e-10 px.
  // The fit works on centred coordinates, so it reproduces every destination to that order
  // (1e-9 px) and the linear part to ~1e-10 / 640 relative (1e-9 allowed).
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const Affine2 truth = random_affine(rng);
    const std::vector<Vec2> src = random_points(rng, 8, 1e6);
    const std::vector<Vec2> dst = mapped(truth, src);
    const auto fit = fit_affine(src, dst);
    ASSERT_TRUE(fit);
    ASSERT_EQ(fit->kind, AffineFitKind::Full);
    for (size_t i = 0; i < src.size(); ++i) EXPECT_LT(norm(fit->map.apply(src[i]) - dst[i]), 1e-9);
    for (int i : {0, 1, 3, 4}) EXPECT_NEAR(fit->map.m[size_t(i)], truth.m[size_t(i)], 1e-9);
  }
}

TEST(FitAffine, TinyMotionsStayAccurate) {
  // A shift of (1e-9, -2e-9) px plus a rotation of 1e-12 rad about (320, 240): the recovered
  // displacement must keep its digits. Pixel values near 640 carry ulp = 1.1e-13 px of rounding,
  // so the displacement is good to ~1e-13; 1e-12 px is allowed.
  std::mt19937 rng(9);
  const double angle = 1e-12;
  const Affine2 about_centre = Affine2::translation({320, 240}) * similarity(angle, 1, {1e-9, -2e-9}) *
                               Affine2::translation({-320, -240});
  const std::vector<Vec2> src = random_points(rng, 8);
  const std::vector<Vec2> dst = mapped(about_centre, src);
  const auto fit = fit_affine(src, dst);
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->kind, AffineFitKind::Full);
  for (const Vec2& p : {Vec2{0, 0}, Vec2{640, 480}, Vec2{320, 240}}) {
    const Vec2 moved = fit->map.apply(p) - p, expected = about_centre.apply(p) - p;
    EXPECT_NEAR(moved[0], expected[0], 1e-12);
    EXPECT_NEAR(moved[1], expected[1], 1e-12);
  }
}

TEST(FitAffine, InvalidInputGivesNothing) {
  const std::vector<Vec2> three{{0, 0}, {1, 0}, {0, 1}}, two{{0, 0}, {1, 0}};
  EXPECT_FALSE(fit_affine({}, {}));
  EXPECT_FALSE(fit_affine(three, two));
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<Vec2> with_nan{{0, 0}, {nan, 0}, {0, 1}}, with_inf{{0, 0}, {1, 0}, {0, inf}};
  EXPECT_FALSE(fit_affine(with_nan, three));
  EXPECT_FALSE(fit_affine(three, with_nan));
  EXPECT_FALSE(fit_affine(three, with_inf));
}

}  // namespace
}  // namespace arpipe
