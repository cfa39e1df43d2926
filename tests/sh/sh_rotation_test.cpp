// ShRotation against its definition: the coefficients of f(R^T w), both projected by an exact
// quadrature; and the group properties (identity, composition, orthogonality, band energy).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_rotation.h"
#include "core/sh/sh_sampling.h"
#include "tests/sh/sh_test_support.h"

namespace arpipe {
namespace {

using sh_test::axis_angle;

// A polynomial of degree 6 in (x, y, z), different per channel: its SH expansion ends at band 6,
// so 7 bands hold it exactly, and so does the expansion of the turned f(R^T w).
Vec3 poly6(const Vec3& w) {
  const double x = w[0], y = w[1], z = w[2];
  return {1 + 0.5 * x - 0.3 * y * z + 0.8 * x * x * y + 0.2 * std::pow(z, 5) - 0.7 * x * y * y * z * z * z,
          0.3 * y + x * z - 0.4 * std::pow(x, 4) + 0.6 * std::pow(y, 6) - 0.2 * x * y * z,
          -0.2 + z * z * z - 0.5 * x * std::pow(y, 5) + 0.9 * x * x * z * z * y};
}

TEST(ShRotation, MatchesProjectionOfTurnedFunction) {
  // Degree-6 polynomials times basis functions of degree <= 6: degree 12. 7 Gauss nodes (exact to
  // 13) and 14 azimuths integrate them exactly, so the two projections agree to rounding: 1e-9
  // leaves room for ~1e3 terms of 1e-15 and the recurrence's rounding over 6 bands.
  const SphereQuadrature q = sphere_product_quadrature(7, 14);
  const ShRgb f = project_quadrature(q, 7, poly6);
  for (const Mat3& R : {axis_angle({1, 2, 3}, 0.7), axis_angle({-0.3, 0.1, 1}, 2.9),
                        axis_angle({0, 1, 0}, std::numbers::pi), sh_test::euler_zyz(0.4, 1.1, -2.0)}) {
    const ShRgb g = project_quadrature(q, 7, [&](const Vec3& w) { return poly6(mat_mul(transpose(R), w)); });
    const ShRgb rotated = ShRotation(R, 7).apply(f);
    for (size_t i = 0; i < g.size(); ++i)
      for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(rotated.c[i][k], g.c[i][k], 1e-9) << "i " << i << " k " << k;
  }
}

TEST(ShRotation, IdentityIsIdentity) {
  const ShRotation r(identity3(), 16);
  for (int l = 0; l < 16; ++l) {
    const std::vector<double>& d = r.band_matrix(l);
    const int n = 2 * l + 1;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) EXPECT_NEAR(d[size_t(i * n + j)], i == j ? 1.0 : 0.0, 1e-14) << "l " << l;
  }
}

// Band matrices multiply like the rotations: D(R1 R2) = D(R1) D(R2); and D D^T = I. Rounding
// accumulates through the recurrence (each band is built from the last): measured 1.3e-15 and
// 2.9e-15 at 16 bands; 1e-12 is the bound that would still catch any wrong sign or factor.
TEST(ShRotation, CompositionAndOrthogonality) {
  const Mat3 r1 = axis_angle({1, -2, 0.5}, 1.3), r2 = axis_angle({0.2, 0.3, -1}, -2.2);
  const ShRotation a(r1, 16), b(r2, 16), ab(mat_mul(r1, r2), 16);
  for (int l = 0; l < 16; ++l) {
    const int n = 2 * l + 1;
    const std::vector<double>&da = a.band_matrix(l), &db = b.band_matrix(l), &dab = ab.band_matrix(l);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double prod = 0, gram = 0;
        for (int k = 0; k < n; ++k) {
          prod += da[size_t(i * n + k)] * db[size_t(k * n + j)];
          gram += da[size_t(i * n + k)] * da[size_t(j * n + k)];
        }
        EXPECT_NEAR(dab[size_t(i * n + j)], prod, 1e-12) << "l " << l;
        EXPECT_NEAR(gram, i == j ? 1.0 : 0.0, 1e-12) << "l " << l;
      }
  }
}

TEST(ShRotation, BandEnergyInvariantAndInPlace) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> gauss;
  std::vector<double> c(256), out(256);
  for (double& v : c) v = gauss(rng);
  const ShRotation r(axis_angle({0.3, 0.9, -0.2}, 0.77), 16);
  r.apply(c, out);
  for (int l = 0; l < 16; ++l) {
    double e0 = 0, e1 = 0;
    for (int m = -l; m <= l; ++m) {
      e0 += c[size_t(sh_index(l, m))] * c[size_t(sh_index(l, m))];
      e1 += out[size_t(sh_index(l, m))] * out[size_t(sh_index(l, m))];
    }
    EXPECT_NEAR(e1, e0, 1e-12 * (1 + e0)) << "l " << l;  // orthogonal D: rounding only
  }
  std::vector<double> same = c;
  r.apply(same, same);  // in place
  for (size_t i = 0; i < 256; ++i) EXPECT_NEAR(same[i], out[i], 1e-15);
  // Fewer bands than the rotation holds: the first 9 only.
  std::vector<double> nine(c.begin(), c.begin() + 9), nine_out(9);
  r.apply(nine, nine_out);
  for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(nine_out[i], out[i], 1e-15);
  std::vector<double> bad(10);
  EXPECT_THROW(r.apply(bad, bad), std::invalid_argument);
}

TEST(ShRotation, ZonalAboutZUnchanged) {
  // A zonal function (only m = 0) is symmetric about z: any turn about z leaves it as it is.
  ShRgb zonal(8);
  for (int l = 0; l < 8; ++l) zonal.c[size_t(sh_index(l, 0))] = {1.0 / (l + 1), -0.5 * l, 0.25};
  for (double angle : {0.1, 1.0, 2.5, -3.0}) {
    const ShRgb out = ShRotation(axis_angle({0, 0, 1}, angle), 8).apply(zonal);
    for (size_t i = 0; i < out.size(); ++i)
      for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(out.c[i][k], zonal.c[i][k], 1e-14);
  }
}

TEST(ShRotation, DeltaAtDMovesToRTimesD) {
  // f = delta at d (c_i = y_i(d)); f(R^T w) is the delta at R d: coefficients y_i(R d).
  const Vec3 d = normalized({0.2, 0.5, -0.8});
  const Mat3 R = axis_angle({1, 1, 0}, 0.9);
  ShRgb delta(3);
  const std::vector<double> y = sh_basis(3, d);
  for (size_t i = 0; i < 9; ++i) delta.c[i] = {y[i], 0, 0};
  const ShRgb out = ShRotation(R, 3).apply(delta);
  const std::vector<double> yr = sh_basis(3, mat_mul(R, d));
  for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(out.c[i][0], yr[i], 1e-14) << i;
}

}  // namespace
}  // namespace arpipe
