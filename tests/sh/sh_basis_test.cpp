// The SH basis of any order: orthonormality by an exact product quadrature (7 and 16 bands), the
// 3-band closed forms, the seed's table (Condon-Shortley phase: (-1)^m times ours), and
// the poles (where the azimuth is undefined).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <stdexcept>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_sampling.h"
#include "tests/sh/sh_test_support.h"

namespace arpipe {
namespace {

// The 3-band closed forms (Green's table, written to 15 digits): Y_0..Y_8 = 0.282095;
// 0.488603 {y, z, x}; 1.092548 xy, 1.092548 yz, 0.315392 (3z^2 - 1), 1.092548 xz, 0.546274 (x^2 - y^2).
std::array<double, 9> closed_form_sh9(const Vec3& d) {
  const double x = d[0], y = d[1], z = d[2];
  return {0.282094791773878, 0.488602511902920 * y, 0.488602511902920 * z, 0.488602511902920 * x,
          1.092548430592079 * x * y, 1.092548430592079 * y * z, 0.315391565252520 * (3 * z * z - 1),
          1.092548430592079 * x * z, 0.546274215296040 * (x * x - y * y)};
}

TEST(ShQuadrature, IntegratesMonomialsExactly) {
  // The integral of z^(2k) over the sphere is 4 pi / (2k + 1); x^2 y^2 gives 4 pi / 15.
  // 8 Gauss-Legendre nodes are exact to degree 15, 16 azimuths to trigonometric degree 15.
  const SphereQuadrature q = sphere_product_quadrature(8, 16);
  for (int k = 0; k <= 7; ++k) {
    double s = 0;
    for (size_t i = 0; i < q.size(); ++i) s += q.weights[i] * std::pow(q.directions[i][2], 2 * k);
    EXPECT_NEAR(s, 4 * std::numbers::pi / (2 * k + 1), 1e-13) << "k = " << k;  // rounding of ~100 terms
  }
  double s = 0;
  for (size_t i = 0; i < q.size(); ++i)
    s += q.weights[i] * q.directions[i][0] * q.directions[i][0] * q.directions[i][1] * q.directions[i][1];
  EXPECT_NEAR(s, 4 * std::numbers::pi / 15, 1e-13);
}

// Products y_i y_j of `bands` bands are polynomials of degree 2 (bands - 1): n_z = bands Gauss
// nodes (exact to 2 bands - 1) and 2 bands azimuths integrate them exactly, so the Gram matrix
// is the identity up to rounding (~1e-15 per term, a few hundred terms).
TEST(ShBasis, OrthonormalSevenBands) {
  const SphereQuadrature q = sphere_product_quadrature(8, 16);
  const std::vector<double> g = sh_test::gram(q.directions, q.weights, 7);
  EXPECT_LT(sh_test::max_deviation_from_identity(g, 49), 1e-12);
}

TEST(ShBasis, OrthonormalSixteenBands) {
  // K_15^m involves 30! / 1: computed as a product it keeps ~1e-15 relative accuracy; a
  // factorial-ratio bug or the recurrence losing accuracy at l = 15 would show here.
  const SphereQuadrature q = sphere_product_quadrature(17, 32);
  const std::vector<double> g = sh_test::gram(q.directions, q.weights, 16);
  EXPECT_LT(sh_test::max_deviation_from_identity(g, 256), 1e-12);
}

TEST(ShBasis, FirstNineEqualClosedForms) {
  // The closed forms' constants are written to 15 digits: agreement to 1e-12 is their precision.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss;
  for (int k = 0; k < 200; ++k) {
    const Vec3 d = normalized({gauss(rng), gauss(rng), gauss(rng)});
    const std::vector<double> y = sh_basis(5, d);
    const std::array<double, 9> ref = closed_form_sh9(d);
    for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(y[i], ref[i], 1e-12) << "i = " << i;
  }
}

TEST(ShBasis, SeedTableIsOursTimesMinusOneToTheM) {
  // The seed's table (Condon-Shortley phase) to 6 digits: the constants' rounding, at most
  // 5e-7 times a polynomial of magnitude <= 3, bounds the difference by 2e-6.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss;
  for (int k = 0; k < 100; ++k) {
    const Vec3 d = normalized({gauss(rng), gauss(rng), gauss(rng)});
    const double x = d[0], y = d[1], z = d[2];
    const double seed[9] = {0.282095,          -0.488603 * y,     0.488603 * z,
                            -0.488603 * x,     1.092548 * x * y,  -1.092548 * y * z,
                            0.315392 * (3 * z * z - 1), -1.092548 * x * z, 0.546274 * (x * x - y * y)};
    const std::vector<double> ours = sh_basis(3, d);
    for (int l = 0; l < 3; ++l)
      for (int m = -l; m <= l; ++m) {
        const size_t i = size_t(sh_index(l, m));
        EXPECT_NEAR(seed[i], (m % 2 == 0 ? 1 : -1) * ours[i], 2e-6) << "l " << l << " m " << m;
      }
  }
}

TEST(ShBasis, PolesOnlyZonal) {
  // At +-z every m != 0 function vanishes (sin theta = 0) and y_l0(+-z) = (+-1)^l sqrt((2l+1)/4pi):
  // evaluated without an angle, nothing is undefined there. Exact up to rounding.
  for (double sz : {1.0, -1.0}) {
    const std::vector<double> y = sh_basis(16, {0, 0, sz});
    for (int l = 0; l < 16; ++l)
      for (int m = -l; m <= l; ++m) {
        const double expected = m == 0 ? std::pow(sz, l) * std::sqrt((2 * l + 1) / (4 * std::numbers::pi)) : 0.0;
        EXPECT_NEAR(y[size_t(sh_index(l, m))], expected, 1e-13) << "l " << l << " m " << m;
      }
  }
}

TEST(ShBasis, SectoralClosedForm) {
  // Closed form of the sectoral functions: sqrt(2) K_l^l (2l-1)!! = sqrt(2 (2l+1)/(4 pi) (2l)!) /
  // (2^l l!) * sqrt(2), times Re (x + i y)^l. Independent of the table: log-gamma. 1e-12 relative.
  const Vec3 d = normalized({0.3, -0.7, 0.2});
  const std::vector<double> y = sh_basis(16, d);
  std::complex<double> p{1, 0};
  for (int l = 1; l < 16; ++l) {
    p *= std::complex<double>(d[0], d[1]);
    const double c = std::sqrt(2.0) * std::exp(0.5 * std::log((2 * l + 1) / (4 * std::numbers::pi)) +
                                               0.5 * std::lgamma(2 * l + 1) - l * std::log(2.0) - std::lgamma(l + 1));
    EXPECT_NEAR(y[size_t(sh_index(l, l))], c * p.real(), 1e-12 * c) << l;
    EXPECT_NEAR(y[size_t(sh_index(l, -l))], c * p.imag(), 1e-12 * c) << l;
  }
}

TEST(ShBasis, RejectsBadArguments) {
  std::vector<double> out(8);
  EXPECT_THROW(sh_basis(3, {0, 0, 1}, out), std::invalid_argument);
  EXPECT_THROW(sh_basis(0, {0, 0, 1}), std::invalid_argument);
  EXPECT_THROW(sh_basis(17, {0, 0, 1}), std::invalid_argument);
}

TEST(ShBasis, EvalAddSampleTruncate) {
  // sh_add_sample of one unit sample then sh_eval at the same direction gives sum_i y_i^2 =
  // bands^2 / (4 pi) (the addition theorem at angle 0); exact up to rounding.
  ShRgb sh(5);
  const Vec3 d = normalized({1, 2, 3});
  sh_add_sample(sh, d, {1, 2, 3}, 1.0);
  const Vec3 e = sh_eval(sh, d);
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(e[k], (k + 1) * 25 / (4 * std::numbers::pi), 1e-12);
  const ShRgb t = sh_truncated(sh, 3), p = sh_truncated(sh, 6);
  ASSERT_EQ(t.size(), 9u);
  ASSERT_EQ(p.size(), 36u);
  for (size_t i = 0; i < 36; ++i) EXPECT_EQ(p.c[i][0], i < 25 ? sh.c[i][0] : 0.0);
  for (size_t i = 0; i < 9; ++i) EXPECT_EQ(t.c[i][1], sh.c[i][1]);
}

}  // namespace
}  // namespace arpipe
