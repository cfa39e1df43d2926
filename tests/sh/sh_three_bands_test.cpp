// The 3 bands a light estimate carries (ShRgb9), by midpoint quadrature on an equirectangular
// grid: orthonormality, the clamped cosine's zonal coefficients and Ramamoorthi & Hanrahan's
// A_l, and irradiance that is exact for a band-limited radiance.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_irradiance.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

// Midpoint quadrature on an equirectangular grid: exact to ~1e-4 for these smooth integrands.
template <typename F>
void for_each_direction(int w, int h, F&& f) {
  for (int j = 0; j < h; ++j) {
    const double theta = kPi * (j + 0.5) / h;
    const double omega = (2 * kPi / w) * (std::cos(kPi * j / h) - std::cos(kPi * (j + 1) / h));
    for (int i = 0; i < w; ++i) {
      const double phi = 2 * kPi * (i + 0.5) / w;
      f(Vec3{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}, omega);
    }
  }
}

TEST(ShThreeBands, OrthonormalByQuadrature) {
  double gram[9][9] = {};
  for_each_direction(256, 128, [&](const Vec3& d, double omega) {
    const std::vector<double> y = sh_basis(3, d);
    for (size_t a = 0; a < 9; ++a)
      for (size_t b = 0; b < 9; ++b) gram[a][b] += y[a] * y[b] * omega;
  });
  for (int a = 0; a < 9; ++a)
    for (int b = 0; b < 9; ++b) EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-4) << a << "," << b;
}

// The clamped cosine max(0, z) has zonal coefficients sqrt(pi)/2, sqrt(pi/3), sqrt(5 pi)/8, and
// A_l = sqrt(4 pi / (2l + 1)) * coefficient_l gives Ramamoorthi & Hanrahan's pi, 2 pi/3, pi/4.
TEST(ShThreeBands, CosineLobeAndConvolutionConstants) {
  std::array<double, 9> c{};
  for_each_direction(512, 256, [&](const Vec3& d, double omega) {
    const std::vector<double> y = sh_basis(3, d);
    for (size_t i = 0; i < 9; ++i) c[i] += std::max(0.0, d[2]) * y[i] * omega;
  });
  EXPECT_NEAR(c[0], std::sqrt(kPi) / 2, 1e-4);
  EXPECT_NEAR(c[2], std::sqrt(kPi / 3), 1e-4);
  EXPECT_NEAR(c[6], std::sqrt(5 * kPi) / 8, 1e-4);
  for (size_t i : {1, 3, 4, 5, 7, 8}) EXPECT_NEAR(c[i], 0, 1e-4) << i;
  EXPECT_NEAR(std::sqrt(4 * kPi) * c[0], kPi, 1e-3);
  EXPECT_NEAR(std::sqrt(4 * kPi / 3) * c[2], 2 * kPi / 3, 1e-3);
  EXPECT_NEAR(std::sqrt(4 * kPi / 5) * c[6], kPi / 4, 1e-3);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(0), kPi);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(1), 2 * kPi / 3);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(2), kPi / 4);
}

// For a radiance of bands 0-2 the SH irradiance is exact (the clamped cosine's higher bands are
// orthogonal to it): compare with the brute-force integral of L(w) max(0, n.w).
TEST(ShThreeBands, IrradianceOfBandLimitedRadianceIsExact) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  ShRgb9 sh{};
  for (Vec3& c : sh) c = {u(rng), u(rng), u(rng)};
  sh[0] = sh[0] + Vec3{4, 4, 4};
  const ShRgb sh3 = from_sh9(sh);
  for (const Vec3 n : {Vec3{0, 0, 1}, Vec3{0, 0, -1}, normalized(Vec3{1, -2, 0.5}), normalized(Vec3{-0.3, 0.2, -1})}) {
    Vec3 brute{0, 0, 0};
    for_each_direction(512, 256, [&](const Vec3& d, double omega) {
      brute = brute + (std::max(0.0, dot(n, d)) * omega) * sh_eval(sh3, d);
    });
    const Vec3 e = sh_irradiance(sh3, n);
    for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(e[k], brute[k], 2e-3 * std::abs(brute[k]) + 1e-3);
  }
  // A constant radiance L gives pi L on every surface.
  ShRgb9 flat{};
  flat[0] = (2 * std::sqrt(kPi)) * Vec3{2, 3, 4};  // the integral of Y_0 over the sphere is 2 sqrt(pi)
  const Vec3 e = sh_irradiance(from_sh9(flat), normalized(Vec3{0.3, 0.4, -0.5}));
  EXPECT_NEAR(e[0], 2 * kPi, 1e-9);
  EXPECT_NEAR(e[2], 4 * kPi, 1e-9);
}

// The fixed-size accumulation adds what the general one adds, and sh_band inverts sh_index.
TEST(ShThreeBands, AddSampleMatchesGeneralAndBandOfIndex) {
  ShRgb9 nine{};
  ShRgb general(3);
  const Vec3 a = normalized(Vec3{0.3, -0.5, 0.8}), b = normalized(Vec3{-1, 0.2, -0.1});
  sh_add_sample(nine, a, {1, 2, 3}, 0.25);
  sh_add_sample(nine, b, {0.5, 0, -1}, 2.0);
  sh_add_sample(general, a, {1, 2, 3}, 0.25);
  sh_add_sample(general, b, {0.5, 0, -1}, 2.0);
  for (size_t i = 0; i < 9; ++i)
    for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(nine[i][k], general.c[i][k], 1e-15) << i << "," << k;
  for (int l = 0; l < kMaxShBands; ++l)
    for (int m = -l; m <= l; ++m) EXPECT_EQ(sh_band(sh_index(l, m)), l) << l << "," << m;
}

}  // namespace
}  // namespace arpipe
