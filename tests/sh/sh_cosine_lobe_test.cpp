// The clamped cosine's zonal coefficients by exact quadrature against the closed-form A_l.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/sh/sh_irradiance.h"
#include "core/sh/sh_sampling.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ShCosineLobe, ClosedFormValues) {
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(0), kPi);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(1), 2 * kPi / 3);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(2), kPi / 4);
  EXPECT_EQ(sh_cosine_lobe_constant(3), 0.0);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(4), -kPi / 24);
  EXPECT_DOUBLE_EQ(sh_cosine_lobe_constant(6), kPi / 64);  // 2 pi / (8 * 5) * 20 / 64
}

TEST(ShCosineLobe, ProjectionMatchesAl) {
  // max(0, z) y_l0 is a polynomial on each hemisphere (degree <= 16 for 16 bands): Gauss-Legendre
  // with 9 nodes per hemisphere (exact to degree 17) integrates it exactly; the m != 0
  // coefficients vanish. So A_l = sqrt(4 pi / (2l + 1)) c_l0 to rounding: 1e-10 is generous.
  const SphereQuadrature q = sphere_product_quadrature(9, 34, true);
  const ShRgb c = project_quadrature(q, 16, [](const Vec3& w) {
    const double g = std::max(0.0, w[2]);
    return Vec3{g, g, g};
  });
  for (int l = 0; l < 16; ++l) {
    for (int m = -l; m <= l; ++m) {
      const double v = c.c[size_t(sh_index(l, m))][0];
      if (m != 0) {
        EXPECT_NEAR(v, 0.0, 1e-12) << "l " << l << " m " << m;
      } else {
        EXPECT_NEAR(std::sqrt(4 * kPi / (2 * l + 1)) * v, sh_cosine_lobe_constant(l), 1e-10) << "l " << l;
      }
    }
  }
  const double a[5] = {kPi, 2 * kPi / 3, kPi / 4, 0, -kPi / 24};
  for (int l = 0; l < 5; ++l)
    EXPECT_NEAR(std::sqrt(4 * kPi / (2 * l + 1)) * c.c[size_t(sh_index(l, 0))][0], a[l], 1e-10) << "l " << l;
}

}  // namespace
}  // namespace arpipe
