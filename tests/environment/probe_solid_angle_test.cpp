// Texel solid angles of the probe layouts: the texels of each layout cover the sphere once (sum
// 4 pi), single texels agree with an independent brute-force integration, and symmetric texels
// get equal solid angles.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>

#include "core/environment/environment_layout.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

struct Case {
  EnvironmentLayout layout;
  int width, height;
};

double total_solid_angle(const Case& c) {
  double sum = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) sum += environment_texel_solid_angle(c.layout, c.width, c.height, x, y);
  return sum;
}

TEST(ProbeSolidAngle, ClosedFormLayoutsSumToFourPi) {
  // Equirect (dphi (cos theta0 - cos theta1)), cube (atan corner formula) and mirror ball (4 x
  // the clipped area, arcsine closed form) are exact: only rounding of ~W H terms remains, so
  // 1e-9 relative is loose by orders of magnitude, yet catches any missing or doubled texel.
  for (const Case& c : {Case{EnvironmentLayout::Equirectangular, 2, 1}, Case{EnvironmentLayout::Equirectangular, 128, 64},
                        Case{EnvironmentLayout::Equirectangular, 2000, 1000}, Case{EnvironmentLayout::CubeCross, 3, 4},
                        Case{EnvironmentLayout::CubeCross, 48, 64}, Case{EnvironmentLayout::CubeCross, 768, 1024},
                        Case{EnvironmentLayout::MirrorBall, 1, 1}, Case{EnvironmentLayout::MirrorBall, 7, 7},
                        Case{EnvironmentLayout::MirrorBall, 64, 64}, Case{EnvironmentLayout::MirrorBall, 1000, 1000}}) {
    const double sum = total_solid_angle(c);
    std::printf("%s %dx%d: sum - 4 pi = %.3g (relative %.3g)\n", std::string(environment_layout_name(c.layout)).c_str(),
                c.width, c.height, sum - 4 * kPi, (sum - 4 * kPi) / (4 * kPi));
    EXPECT_NEAR(sum, 4 * kPi, 1e-9 * 4 * kPi) << environment_layout_name(c.layout) << " " << c.width;
  }
}

TEST(ProbeSolidAngle, AngularMapQuadratureSumsToFourPi) {
  // The angular map's density pi sin(pi r) / r has no closed-form integral over a clipped square:
  // texels inside the disk use tensor Gauss-Legendre (8 x 8, or 4 x 4 from N = 40), rim texels
  // 16 x 16 Gauss-Legendre on pieces where the clipped chord is smooth (with a w^2 substitution
  // where the chord ends in a sqrt at u = +-1). The density is entire with k-th derivatives of
  // order pi^(k+1), so the rules' remainders (h^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^3) pi^(2n+1) per
  // unit area) stay below 1e-13 relative at these texel widths h; allow 1e-10 relative for the sum,
  // which also covers the round-off of N^2 terms.
  for (int n : {1, 2, 3, 8, 64, 301}) {
    const double sum = total_solid_angle({EnvironmentLayout::AngularMap, n, n});
    std::printf("angular %dx%d: sum - 4 pi = %.3g (relative %.3g)\n", n, n, sum - 4 * kPi, (sum - 4 * kPi) / (4 * kPi));
    EXPECT_NEAR(sum, 4 * kPi, 1e-10 * 4 * kPi) << n;
  }
}

// Brute force: the texel split into k x k sub-squares, each sub-square's solid angle as the
// spherical quadrilateral of its four corner directions (two triangles, Van Oosterom-Strackee);
// for sub-squares cut by the disk's rim the corners outside are skipped, so only fully inside
// sub-squares are summed, and the comparison allows for the uncovered sliver.
double spherical_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 2 * std::atan2(std::abs(dot(a, cross(b, c))), 1 + dot(a, b) + dot(b, c) + dot(c, a));
}

double brute_force(const Case& c, int x, int y, int k) {
  double sum = 0;
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const double x0 = x - 0.5 + double(i) / k, x1 = x - 0.5 + double(i + 1) / k;
      const double y0 = y - 0.5 + double(j) / k, y1 = y - 0.5 + double(j + 1) / k;
      const auto a = environment_pixel_direction(c.layout, c.width, c.height, x0, y0);
      const auto b = environment_pixel_direction(c.layout, c.width, c.height, x1, y0);
      const auto d = environment_pixel_direction(c.layout, c.width, c.height, x1, y1);
      const auto e = environment_pixel_direction(c.layout, c.width, c.height, x0, y1);
      if (!a || !b || !d || !e) continue;
      sum += spherical_triangle(*a, *b, *d) + spherical_triangle(*a, *d, *e);
    }
  return sum;
}

TEST(ProbeSolidAngle, SingleTexelsMatchBruteForce) {
  // Interior texels: the polygon approximation of each sub-square converges as O(1/k^2); with
  // k = 64 the relative difference is below 1e-4 for these sizes (measured on the closed-form
  // layouts first, where the formulas are exact; printed below). Rim texels of the disk layouts
  // are partly covered by the brute force only, so it must come out smaller, by at most the
  // sub-squares the rim crosses: an arc of length <= sqrt(2) texels crosses at most 3 k + 2 of
  // the k^2, each holding at most (max density) (2 / N)^2 / k^2 sr, the density being 4 for the
  // mirror ball and at most pi^2 for the angular map.
  const std::vector<std::pair<Case, std::vector<std::array<int, 2>>>> cases = {
      {{EnvironmentLayout::Equirectangular, 32, 16}, {{0, 0}, {5, 3}, {16, 8}, {31, 15}}},
      {{EnvironmentLayout::CubeCross, 24, 32}, {{8, 0}, {12, 12}, {15, 15}, {0, 8}, {8, 31}, {23, 15}}},
      {{EnvironmentLayout::MirrorBall, 16, 16}, {{8, 8}, {3, 8}, {1, 7}, {4, 4}, {0, 7}, {2, 2}, {13, 1}}},
      {{EnvironmentLayout::AngularMap, 16, 16}, {{8, 8}, {7, 7}, {3, 8}, {1, 7}, {4, 4}, {0, 7}, {2, 2}, {13, 1}}},
  };
  for (const auto& [c, texels] : cases)
    for (const auto& [x, y] : texels) {
      const double exact = environment_texel_solid_angle(c.layout, c.width, c.height, x, y);
      const double brute = brute_force(c, x, y, 64);
      const bool interior = brute_force(c, x, y, 1) > 0;  // all four corners inside the valid region
      std::printf("%s %dx%d texel (%d, %d): %.10g vs brute force %.10g (%s)\n",
                  std::string(environment_layout_name(c.layout)).c_str(), c.width, c.height, x, y, exact, brute,
                  interior ? "interior" : "rim");
      if (interior) {
        EXPECT_NEAR(brute, exact, 1e-4 * exact) << environment_layout_name(c.layout) << " " << x << "," << y;
      } else {
        EXPECT_LE(brute, exact * (1 + 1e-4));
        const double density = c.layout == EnvironmentLayout::MirrorBall ? 4 : kPi * kPi;
        const double skipped = (3.0 * 64 + 2) / (64.0 * 64.0) * density * std::pow(2.0 / c.width, 2);
        EXPECT_GE(brute, exact - skipped - 1e-4 * exact);
      }
    }
}

TEST(ProbeSolidAngle, RimTexelsMatchFineIntegration) {
  // Rim texels of the disk layouts against plain midpoint sums in (u, v), which share no code with
  // the layout: the mirror ball's 4 x clipped area from 10^5 u-slices with the chord clipped
  // exactly in v (the chord length is Lipschitz away from tangency: error ~ 1e-9 relative); the
  // angular map's density pi sin(pi r) / r at k x k = 1000 x 1000 sub-cell centres inside the disk.
  // There the density falls to 0 linearly at the rim, so the ~3k cells the rim cuts each err by
  // at most pi^2 (h / k)^3 and the midpoint rule elsewhere by ~(h / k)^2 of the texel: allow 1e-5
  // of the texel's unclipped solid-angle scale pi^2 h^2 (h = 2 / N, the texel's width in (u, v)).
  const int n = 16;
  const double h = 2.0 / n;
  for (const auto& [x, y] : std::vector<std::array<int, 2>>{{0, 7}, {2, 2}, {13, 1}, {7, 0}, {1, 4}}) {
    const double u0 = -1 + h * x, v1 = 1 - h * y;
    const int slices = 100000;
    double area = 0;
    for (int i = 0; i < slices; ++i) {
      const double u = u0 + h * (i + 0.5) / slices, s = std::sqrt(std::max(0.0, 1 - u * u));
      area += std::max(0.0, std::min(v1, s) - std::max(v1 - h, -s)) * h / slices;
    }
    EXPECT_NEAR(environment_texel_solid_angle(EnvironmentLayout::MirrorBall, n, n, x, y), 4 * area, 1e-8 * 4 * h * h) << x << "," << y;
    const int k = 1000;
    double omega = 0;
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        const double u = u0 + h * (i + 0.5) / k, v = v1 - h * (j + 0.5) / k, r = std::hypot(u, v);
        if (r <= 1) omega += kPi * std::sin(kPi * r) / r * (h / k) * (h / k);
      }
    const double exact = environment_texel_solid_angle(EnvironmentLayout::AngularMap, n, n, x, y);
    std::printf("rim texel (%d, %d): mirror %.12g vs %.12g, angular %.12g vs %.12g\n", x, y,
                environment_texel_solid_angle(EnvironmentLayout::MirrorBall, n, n, x, y), 4 * area, exact, omega);
    EXPECT_NEAR(exact, omega, 1e-5 * kPi * kPi * h * h) << x << "," << y;
  }
}

TEST(ProbeSolidAngle, SymmetricTexelsAgreeAndBlankTexelsAreZero) {
  // Mirror-image texels (left/right, top/bottom) have equal solid angles in every layout's map.
  for (const Case& c : {Case{EnvironmentLayout::AngularMap, 9, 9}, Case{EnvironmentLayout::MirrorBall, 10, 10},
                        Case{EnvironmentLayout::Equirectangular, 20, 10}})
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        const double a = environment_texel_solid_angle(c.layout, c.width, c.height, x, y);
        EXPECT_NEAR(a, environment_texel_solid_angle(c.layout, c.width, c.height, c.width - 1 - x, y), 1e-14);
        EXPECT_NEAR(a, environment_texel_solid_angle(c.layout, c.width, c.height, x, c.height - 1 - y), 1e-14);
      }
  // Cube: the blank squares hold nothing; every face holds 4 pi / 6.
  const int F = 8;
  for (int row = 0; row < 4; ++row)
    for (int column = 0; column < 3; ++column) {
      double face = 0;
      for (int y = row * F; y < (row + 1) * F; ++y)
        for (int x = column * F; x < (column + 1) * F; ++x) face += environment_texel_solid_angle(EnvironmentLayout::CubeCross, 3 * F, 4 * F, x, y);
      const bool is_face = column == 1 || row == 1;
      EXPECT_NEAR(face, is_face ? 4 * kPi / 6 : 0, 1e-12) << column << "," << row;
    }
  // Outside the image: 0.
  EXPECT_EQ(environment_texel_solid_angle(EnvironmentLayout::AngularMap, 8, 8, 8, 0), 0);
  EXPECT_EQ(environment_texel_solid_angle(EnvironmentLayout::AngularMap, 8, 8, 0, 0), 0);  // corner texel, outside the disk
}

TEST(ProbeSolidAngle, AngularMapCostForALargeProbe) {
  // Informational: the quadrature's cost on a 500 x 500 angular map (Debevec's are 1000 x 1000:
  // four times this).
  const auto start = std::chrono::steady_clock::now();
  const double sum = total_solid_angle({EnvironmentLayout::AngularMap, 500, 500});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("angular 500x500: %.2f s, relative error of the sum %.3g\n", seconds, (sum - 4 * kPi) / (4 * kPi));
  EXPECT_NEAR(sum, 4 * kPi, 1e-10 * 4 * kPi);
}

}  // namespace
}  // namespace arpipe
