// RapidCheck properties of ShRotation over random rotations, including the degenerate ones:
// identity, half turns about the axes and about random axes, tiny angles, and Euler beta = 0 or pi
// (where z-y-z angles are not unique and angle-based formulas divide by sin beta).
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_rotation.h"
#include "tests/sh/sh_test_support.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kBands = 8;

rc::Gen<double> in_range(double lo, double hi) {
  return rc::gen::map(rc::gen::inRange<int64_t>(0, 1'000'000'001),
                      [lo, hi](int64_t k) { return lo + (hi - lo) * static_cast<double>(k) / 1e9; });
}
rc::Gen<Vec3> unit_vector() {
  return rc::gen::map(rc::gen::tuple(in_range(-1, 1), in_range(0, 2 * kPi)), [](std::tuple<double, double> t) {
    const auto [z, phi] = t;
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    return Vec3{r * std::cos(phi), r * std::sin(phi), z};
  });
}
// Random rotations, a third of them degenerate in one of the named ways.
rc::Gen<Mat3> any_rotation() {
  return rc::gen::oneOf(
      rc::gen::map(rc::gen::tuple(unit_vector(), in_range(-kPi, kPi)),
                   [](std::tuple<Vec3, double> t) { return sh_test::axis_angle(std::get<0>(t), std::get<1>(t)); }),
      rc::gen::just(identity3()),
      rc::gen::map(rc::gen::inRange(0, 3),
                   [](int axis) {
                     Vec3 a{0, 0, 0};
                     a[size_t(axis)] = 1;
                     return sh_test::axis_angle(a, kPi);
                   }),
      rc::gen::map(unit_vector(), [](const Vec3& a) { return sh_test::axis_angle(a, kPi); }),
      rc::gen::map(rc::gen::tuple(unit_vector(), in_range(-1e-9, 1e-9)),
                   [](std::tuple<Vec3, double> t) { return sh_test::axis_angle(std::get<0>(t), std::get<1>(t)); }),
      rc::gen::map(rc::gen::tuple(in_range(-kPi, kPi), rc::gen::element(0.0, kPi), in_range(-kPi, kPi)),
                   [](std::tuple<double, double, double> t) {
                     return sh_test::euler_zyz(std::get<0>(t), std::get<1>(t), std::get<2>(t));
                   }));
}

// A point source's coefficients y(d) turned by R must be y(R d) (the definition, sampled at the
// delta: exact, no quadrature). Rounding through 7 recurrence steps stays far below 1e-11.
RC_GTEST_PROP(ShRotationProperties, DeltaFollowsTheRotation, ()) {
  const Mat3 R = *any_rotation();
  const Vec3 d = *unit_vector();
  const std::vector<double> y = sh_basis(kBands, d);
  std::vector<double> out(y.size());
  ShRotation(R, kBands).apply(y, out);
  const std::vector<double> expected = sh_basis(kBands, mat_mul(R, d));
  for (size_t i = 0; i < y.size(); ++i) RC_ASSERT(std::abs(out[i] - expected[i]) < 1e-11);
}

RC_GTEST_PROP(ShRotationProperties, ComposesAndIsOrthogonal, ()) {
  const Mat3 r1 = *any_rotation(), r2 = *any_rotation();
  const ShRotation a(r1, kBands), b(r2, kBands), ab(mat_mul(r1, r2), kBands);
  for (int l = 0; l < kBands; ++l) {
    const int n = 2 * l + 1;
    const std::vector<double>&da = a.band_matrix(l), &db = b.band_matrix(l), &dab = ab.band_matrix(l);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        double prod = 0, gram = 0;
        for (int k = 0; k < n; ++k) {
          prod += da[size_t(i * n + k)] * db[size_t(k * n + j)];
          gram += da[size_t(i * n + k)] * da[size_t(j * n + k)];
        }
        RC_ASSERT(std::abs(dab[size_t(i * n + j)] - prod) < 1e-12);
        RC_ASSERT(std::abs(gram - (i == j ? 1.0 : 0.0)) < 1e-12);
      }
  }
}

RC_GTEST_PROP(ShRotationProperties, InverseUndoes, ()) {
  const Mat3 R = *any_rotation();
  const std::vector<double> c = *rc::gen::container<std::vector<double>>(size_t(kBands * kBands), in_range(-1, 1));
  std::vector<double> turned(c.size()), back(c.size());
  ShRotation(R, kBands).apply(c, turned);
  ShRotation(transpose(R), kBands).apply(turned, back);
  for (size_t i = 0; i < c.size(); ++i) RC_ASSERT(std::abs(back[i] - c[i]) < 1e-12);
}

}  // namespace
}  // namespace arpipe
