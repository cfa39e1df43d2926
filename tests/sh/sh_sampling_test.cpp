// The seed's sampler and Monte Carlo projection (seed 002 sec. 2.4-2.6) against its own sanity
// numbers: the sampled Gram matrix and the unshadowed transfer A_l y_lm(n) at 200 x 200.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_irradiance.h"
#include "core/sh/sh_sampling.h"
#include "tests/sh/sh_test_support.h"

namespace arpipe {
namespace {

TEST(ShSampling, LayoutAndDeterminism) {
  const SphereSamples a = stratified_sphere_samples(20, 4, 42);
  const SphereSamples b = stratified_sphere_samples(20, 4, 42);
  const SphereSamples c = stratified_sphere_samples(20, 4, 43);
  ASSERT_EQ(a.size(), 400u);
  ASSERT_EQ(a.basis.size(), 400u * 16u);
  EXPECT_DOUBLE_EQ(a.weight, 4 * std::numbers::pi / 400);
  EXPECT_EQ(a.directions, b.directions);
  EXPECT_NE(a.directions, c.directions);
  for (size_t j = 0; j < a.size(); ++j) {
    EXPECT_NEAR(norm(a.directions[j]), 1.0, 1e-15);
    const std::vector<double> y = sh_basis(4, a.directions[j]);
    for (size_t i = 0; i < 16; ++i) EXPECT_EQ(a.basis_at(j)[i], y[i]);
  }
  // Cell (i, j) holds a in [i/N, (i+1)/N): z = 1 - 2a lies in its band of the sphere.
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      const double z = a.directions[size_t(i * 20 + j)][2];
      EXPECT_LE(z, 1 - 2.0 * i / 20 + 1e-15);
      EXPECT_GT(z, 1 - 2.0 * (i + 1) / 20 - 1e-15);
    }
  EXPECT_THROW(stratified_sphere_samples(0, 3, 1), std::invalid_argument);
  EXPECT_THROW(stratified_sphere_samples(10, 17, 1), std::invalid_argument);
}

// The standard deviations of the jittered estimators sum_cells (4 pi / T) g_k(u_cell), u_cell
// uniform in its cell of the (a, b) square: sigma_k^2 = sum_cells (4 pi / T)^2 Var_cell(g_k),
// the within-cell variance taken on a 4 x 4 sub-grid of each cell. Independent of the sampler's
// code (the mapping is written out again here). g returns all the g_k at one direction.
std::vector<double> stratified_sigmas(int n, size_t count, const std::function<void(const Vec3&, double*)>& g) {
  constexpr int kSub = 4;
  const double w = 4 * std::numbers::pi / (double(n) * n);
  std::vector<double> var(count, 0.0), s(count), s2(count), v(count);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      std::fill(s.begin(), s.end(), 0.0);
      std::fill(s2.begin(), s2.end(), 0.0);
      for (int p = 0; p < kSub; ++p)
        for (int q = 0; q < kSub; ++q) {
          const double a = (i + (p + 0.5) / kSub) / n, b = (j + (q + 0.5) / kSub) / n;
          const double theta = 2 * std::acos(std::sqrt(1 - a)), phi = 2 * std::numbers::pi * b;
          g({std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}, v.data());
          for (size_t k = 0; k < count; ++k) {
            s[k] += v[k];
            s2[k] += v[k] * v[k];
          }
        }
      for (size_t k = 0; k < count; ++k) {
        const double mean = s[k] / (kSub * kSub);
        var[k] += w * w * std::max(0.0, s2[k] / (kSub * kSub) - mean * mean);
      }
    }
  for (double& x : var) x = std::sqrt(x);
  return var;
}

// The seed's sanity numbers (200 x 200 jittered, its Python generator with seed 1): Gram matrix
// within 2.8e-4 of the identity, unshadowed transfer within ~5e-5. Those are single draws of a
// random estimator; the tolerance here is 4 standard deviations of that estimator, computed
// above for each entry (sigma ~0.5e-4 .. 1.4e-4 at N = 200). Measured with mt19937_64 seed 1:
// Gram max deviation 3.4e-4; transfer errors 2.5e-5 .. 1.8e-4, all within 1.5 sigma (and the RMS
// over 20 seeds matched these sigmas). The seed's "5e-5 for all nine" is what the cell centres
// (no jitter, a midpoint rule) give: 5.4e-5 for this normal, checked below.
TEST(ShSampling, SampledGramWithinFourSigma) {
  const SphereSamples s = stratified_sphere_samples(200, 3, 1);
  const std::vector<double> w(s.size(), s.weight);
  const std::vector<double> g = sh_test::gram(s.directions, w, 3);
  RecordProperty("max_deviation", std::to_string(sh_test::max_deviation_from_identity(g, 9)));
  const std::vector<double> sigma = stratified_sigmas(200, 81, [](const Vec3& d, double* out) {
    std::array<double, 9> y;
    sh_basis(3, d, y);
    for (size_t i = 0; i < 81; ++i) out[i] = y[i / 9] * y[i % 9];
  });
  for (size_t i = 0; i < 81; ++i)
    // + 1e-12: rounding of the 40000-term sums, for the constant y_00^2 whose sigma is 0.
    EXPECT_LT(std::abs(g[i] - (i / 9 == i % 9 ? 1.0 : 0.0)), 4 * sigma[i] + 1e-12) << i / 9 << " " << i % 9;
}

TEST(ShSampling, UnshadowedTransferIsCosineLobe) {
  // Projecting max(0, n.w) gives T_lm = A_l y_lm(n) (A = pi, 2 pi / 3, pi / 4).
  const Vec3 n = normalized({0.3, -0.5, 0.81});
  const auto lobe = [&](const Vec3& w) {
    const double g = std::max(0.0, dot(n, w));
    return Vec3{g, g, g};
  };
  const std::vector<double> y = sh_basis(3, n);
  // Jittered, seed 1: within 4 sigma of each coefficient's stratified standard deviation.
  const ShRgb t = project_samples(stratified_sphere_samples(200, 3, 1), lobe);
  const std::vector<double> sigma = stratified_sigmas(200, 9, [&](const Vec3& d, double* out) {
    sh_basis(3, d, std::span<double>(out, 9));
    for (size_t i = 0; i < 9; ++i) out[i] *= lobe(d)[0];
  });
  double worst = 0;
  for (int l = 0; l < 3; ++l)
    for (int m = -l; m <= l; ++m) {
      const size_t i = size_t(sh_index(l, m));
      const double err = std::abs(t.c[i][0] - sh_cosine_lobe_constant(l) * y[i]);
      EXPECT_LT(err, 4 * sigma[i]) << "l " << l << " m " << m << " sigma " << sigma[i];
      worst = std::max(worst, err);
    }
  RecordProperty("jittered_max_error", std::to_string(worst));
  // Cell centres: a deterministic midpoint rule in z (error ~ (2/N)^2 / 24 times the integrand's
  // second derivative, plus the kink at the terminator) and exact in phi for these low degrees:
  // the test is that rate itself: 400 x 400 must be 4 times closer (within 10 %).
  const auto centre_error = [&](int N) {
    const ShRgb c = project_samples(stratified_sphere_samples(N, 3, 0, false), lobe);
    double e = 0;
    for (int l = 0; l < 3; ++l)
      for (int m = -l; m <= l; ++m) {
        const size_t i = size_t(sh_index(l, m));
        e = std::max(e, std::abs(c.c[i][0] - sh_cosine_lobe_constant(l) * y[i]));
      }
    return e;
  };
  const double e200 = centre_error(200), e400 = centre_error(400);
  RecordProperty("centre_max_error_200", std::to_string(e200));
  EXPECT_NEAR(e200 / e400, 4.0, 0.4);
}

}  // namespace
}  // namespace arpipe
