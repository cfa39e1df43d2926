// Probe layouts: anchor points worked out from the conventions in probe_layout.h, round trips
// direction -> pixel -> direction and pixel -> direction -> pixel, continuity across the cube's
// face edges (including the folds between faces that are not neighbours in the image) and the
// equirect seam, valid regions, and the shape checks.
#include "core/environment/environment_layout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

using hdr_test::angle_between;
using hdr_test::random_direction;

constexpr double kPi = std::numbers::pi;
constexpr std::array<EnvironmentLayout, 4> kLayouts = {EnvironmentLayout::AngularMap, EnvironmentLayout::MirrorBall,
                                                 EnvironmentLayout::Equirectangular, EnvironmentLayout::CubeCross};

struct Size {
  int width, height;
};
Size size_of(EnvironmentLayout layout, int n) {
  switch (layout) {
    case EnvironmentLayout::Equirectangular: return {2 * n, n};
    case EnvironmentLayout::CubeCross: return {3 * n, 4 * n};
    default: return {n, n};
  }
}

void expect_direction(EnvironmentLayout layout, Size s, double px, double py, const Vec3& expected) {
  const std::optional<Vec3> d = environment_pixel_direction(layout, s.width, s.height, px, py);
  ASSERT_TRUE(d.has_value()) << environment_layout_name(layout) << " at " << px << "," << py;
  EXPECT_LT(angle_between(*d, normalized(expected)), 1e-12)
      << environment_layout_name(layout) << " at " << px << "," << py << ": got " << (*d)[0] << "," << (*d)[1] << "," << (*d)[2];
}

void expect_pixel(EnvironmentLayout layout, Size s, const Vec3& direction, double px, double py) {
  const Vec2 p = environment_direction_pixel(layout, s.width, s.height, normalized(direction));
  EXPECT_NEAR(p[0], px, 1e-9) << environment_layout_name(layout);
  EXPECT_NEAR(p[1], py, 1e-9) << environment_layout_name(layout);
}

TEST(EnvironmentLayout, NamesRoundTrip) {
  for (EnvironmentLayout layout : kLayouts) EXPECT_EQ(parse_environment_layout(environment_layout_name(layout)), layout);
  EXPECT_EQ(parse_environment_layout("angular"), EnvironmentLayout::AngularMap);
  EXPECT_EQ(parse_environment_layout("mirror-ball"), EnvironmentLayout::MirrorBall);
  EXPECT_EQ(parse_environment_layout("equirect"), EnvironmentLayout::Equirectangular);
  EXPECT_EQ(parse_environment_layout("cube-cross"), EnvironmentLayout::CubeCross);
  EXPECT_FALSE(parse_environment_layout("latlong").has_value());
  EXPECT_FALSE(parse_environment_layout("").has_value());
}

TEST(EnvironmentLayout, AngularMapAnchors) {
  // N = 64: centre pixel position 31.5; u = 2 (px + 0.5) / 64 - 1, v = 1 - 2 (py + 0.5) / 64.
  const Size s{64, 64};
  const auto L = EnvironmentLayout::AngularMap;
  expect_direction(L, s, 31.5, 31.5, {0, 0, -1});  // centre: forward
  expect_pixel(L, s, {0, 0, -1}, 31.5, 31.5);
  // Up: 90 degrees from forward, r = 1/2 straight up: v = 0.5 -> py = (1 - 0.5) 32 - 0.5 = 15.5.
  expect_direction(L, s, 31.5, 15.5, {0, 1, 0});
  expect_pixel(L, s, {0, 1, 0}, 31.5, 15.5);
  // Right: u = 0.5 -> px = 1.5 * 32 - 0.5 = 47.5.
  expect_direction(L, s, 47.5, 31.5, {1, 0, 0});
  expect_pixel(L, s, {1, 0, 0}, 47.5, 31.5);
  // 45 degrees up-left of forward... (u, v) = (-0.25 / sqrt2, 0.25 / sqrt2) * sqrt2 -> r = 1/4 along
  // (-1, 1) / sqrt2: D = (sin(pi/4) (-1/sqrt2), sin(pi/4) (1/sqrt2), -cos(pi/4)) = (-1/2, 1/2, -1/sqrt2).
  const double q = 0.25 / std::sqrt(2.0);
  expect_direction(L, s, (-q + 1) * 32 - 0.5, (1 - q) * 32 - 0.5, {-0.5, 0.5, -1 / std::sqrt(2.0)});
  // The rim is the back direction everywhere: at r = 1 - 1e-14 (just inside, so rounding cannot
  // put the point outside the disk) the angle from back is pi * 1e-14.
  for (double t : {0.0, 0.3, 1.7, 3.0, 5.5}) {
    const double r = 1 - 1e-14;
    expect_direction(L, s, (r * std::cos(t) + 1) * 32 - 0.5, (1 - r * std::sin(t)) * 32 - 0.5, {0, 0, 1});
  }
  expect_pixel(L, s, {0, 0, 1}, 31.5, 63.5);
  // Outside the disk: the image's corners.
  EXPECT_FALSE(environment_pixel_direction(L, 64, 64, 0, 0).has_value());
  EXPECT_FALSE(environment_pixel_direction(L, 64, 64, 63, 63).has_value());
}

TEST(EnvironmentLayout, MirrorBallAnchors) {
  const Size s{64, 64};
  const auto L = EnvironmentLayout::MirrorBall;
  expect_direction(L, s, 31.5, 31.5, {0, 0, 1});  // centre: back, towards the camera
  expect_pixel(L, s, {0, 0, 1}, 31.5, 31.5);
  // Up (90 degrees from +z): r = sin(45 deg) = 1/sqrt2 straight up; N = (0, 1/sqrt2, 1/sqrt2),
  // R = 2 (N.V) N - V = (0, 1, 1) - (0, 0, 1) = (0, 1, 0).
  const double h = 1 / std::sqrt(2.0);
  expect_direction(L, s, 31.5, (1 - h) * 32 - 0.5, {0, 1, 0});
  expect_pixel(L, s, {0, 1, 0}, 31.5, (1 - h) * 32 - 0.5);
  expect_direction(L, s, (1 + h) * 32 - 0.5, 31.5, {1, 0, 0});  // right
  expect_pixel(L, s, {1, 0, 0}, (1 + h) * 32 - 0.5, 31.5);
  // u = 0.5: N = (0.5, 0, sqrt(0.75)), R = (2 * sqrt(.75) * 0.5, 0, 2 * 0.75 - 1) = (sqrt(.75), 0, 0.5).
  expect_direction(L, s, 1.5 * 32 - 0.5, 31.5, {std::sqrt(0.75), 0, 0.5});
  // The rim shows forward (-z). At r = 1 - 1e-14 the reflected direction is 2 acos(r) ~ 2 sqrt(2e-14)
  // = 2.8e-7 rad from -z (the map is that steep at the rim); allow 3e-7 (plus rounding of the
  // pixel position, which sqrt(1 - r^2) magnifies to ~1e-8).
  for (double t : {0.0, 0.3, 1.7, 3.0, 5.5}) {
    const double r = 1 - 1e-14;
    const auto d = environment_pixel_direction(L, 64, 64, (r * std::cos(t) + 1) * 32 - 0.5, (1 - r * std::sin(t)) * 32 - 0.5);
    ASSERT_TRUE(d.has_value());
    EXPECT_LT(angle_between(*d, {0, 0, -1}), 3e-7) << t;
  }
  expect_direction(L, s, 31.5, 63.5, {0, 0, -1});  // exactly on the rim (bottom): exactly -z
  expect_pixel(L, s, {0, 0, -1}, 31.5, 63.5);
  EXPECT_FALSE(environment_pixel_direction(L, 64, 64, 0, 0).has_value());
}

TEST(EnvironmentLayout, EquirectAnchors) {
  const Size s{128, 64};
  const auto L = EnvironmentLayout::Equirectangular;
  expect_direction(L, s, 63.5, 31.5, {0, 0, -1});  // image centre (u = v = 1/2): forward
  expect_pixel(L, s, {0, 0, -1}, 63.5, 31.5);
  expect_direction(L, s, 95.5, 31.5, {1, 0, 0});   // u = 3/4: phi = pi/2, right
  expect_pixel(L, s, {1, 0, 0}, 95.5, 31.5);
  expect_direction(L, s, 31.5, 31.5, {-1, 0, 0});  // u = 1/4: left
  expect_direction(L, s, 40, -0.5, {0, 1, 0});     // top edge: up
  expect_direction(L, s, 40, 63.5, {0, -1, 0});    // bottom edge: down
  expect_pixel(L, s, {0, 1, 0}, 63.5, -0.5);       // the poles map to the centre column
  expect_direction(L, s, -0.5, 31.5, {0, 0, 1});   // seam: back
  expect_direction(L, s, 127.5, 31.5, {0, 0, 1});
  // 45 degrees up, forward: v = 1/4 -> py = 15.5.
  expect_direction(L, s, 63.5, 15.5, {0, 1, -1});
  EXPECT_FALSE(environment_pixel_direction(L, 128, 64, 128, 10).has_value());
}

TEST(EnvironmentLayout, CubeCrossAnchorsAndFolds) {
  // F = 16, image 48 x 64. Face squares (column, row): +y (1,0), -x (0,1), -z (1,1), +x (2,1),
  // -y (1,2), +z (1,3). Face centres first.
  const int F = 16;
  const Size s{3 * F, 4 * F};
  const auto L = EnvironmentLayout::CubeCross;
  const auto at = [F](double column, double row) { return Vec2{column * F - 0.5, row * F - 0.5}; };
  const std::vector<std::pair<Vec2, Vec3>> anchors = {
      {at(1.5, 0.5), {0, 1, 0}}, {at(0.5, 1.5), {-1, 0, 0}}, {at(1.5, 1.5), {0, 0, -1}},
      {at(2.5, 1.5), {1, 0, 0}}, {at(1.5, 2.5), {0, -1, 0}}, {at(1.5, 3.5), {0, 0, 1}},
      // Edges between faces that are neighbours in the image.
      {at(1.5, 1), {0, 1, -1}},   // front top = up bottom
      {at(2, 1.5), {1, 0, -1}},   // front right = right's left
      {at(1, 1.5), {-1, 0, -1}},  // front left = left's right
      {at(1.5, 2), {0, -1, -1}},  // front bottom = down top
      {at(1.5, 3), {0, -1, 1}},   // down bottom = back top (the back face is upside down)
      // Far edges of the faces, which meet other faces only once the cross is folded.
      {at(1.5, 0), {0, 1, 1}},    // up's top edge ...
      {at(1.5, 4), {0, 1, 1}},    // ... is the back's bottom edge
      {at(3, 1.5), {1, 0, 1}},    // right's right edge ...
      {at(2, 3.5), {1, 0, 1}},    // ... is the back's right edge
      {at(0, 1.5), {-1, 0, 1}},   // left's left edge ...
      {at(1, 3.5), {-1, 0, 1}},   // ... is the back's left edge
      {at(2, 0.5), {1, 1, 0}},    // up's right edge ...
      {at(2.5, 1), {1, 1, 0}},    // ... is the right's top edge
      {at(1, 0.5), {-1, 1, 0}},   // up's left edge = left's top edge
      {at(0.5, 1), {-1, 1, 0}},
      {at(2, 2.5), {1, -1, 0}},   // down's right edge = right's bottom edge
      {at(2.5, 2), {1, -1, 0}},
      {at(1, 2.5), {-1, -1, 0}},  // down's left edge = left's bottom edge
      {at(0.5, 2), {-1, -1, 0}},
      // Corners: front top-right; back's image top-left is (-1, -1, 1).
      {at(2, 1), {1, 1, -1}},
      {at(1, 3), {-1, -1, 1}},
  };
  for (const auto& [p, d] : anchors) expect_direction(L, s, p[0], p[1], d);
  for (int face = 0; face < 6; ++face) {
    const Vec2 centre = anchors[static_cast<size_t>(face)].first;
    expect_pixel(L, s, anchors[static_cast<size_t>(face)].second, centre[0], centre[1]);
  }
  // Blank squares and outside.
  EXPECT_FALSE(environment_pixel_direction(L, s.width, s.height, at(0.5, 0.5)[0], at(0.5, 0.5)[1]).has_value());
  EXPECT_FALSE(environment_pixel_direction(L, s.width, s.height, at(2.5, 3.5)[0], at(2.5, 3.5)[1]).has_value());
  EXPECT_FALSE(environment_texel_valid(L, s.width, s.height, 0, 0));
  EXPECT_TRUE(environment_texel_valid(L, s.width, s.height, F, 0));
  // The face of a direction: largest component.
  EXPECT_EQ(cube_cross_face_cell({0, 0, 1}), (std::array<int, 2>{1, 3}));
  EXPECT_EQ(cube_cross_face_cell(normalized({0.5, -0.9, 0.2})), (std::array<int, 2>{1, 2}));
}

TEST(EnvironmentLayout, DirectionPixelDirectionRoundTrip) {
  // Random directions plus the special ones (axes, back/forward, cube edges and corners, the
  // seam). Measured worst error is printed; the bound 1e-12 rad is a few thousand ulps, well above
  // double rounding in these trigonometric chains (the mirror ball near -z loses
  // eps / sqrt(1 - r^2), still below 1e-12 for directions more than 1e-4 rad from -z).
  std::mt19937_64 rng(42);
  std::vector<Vec3> directions;
  for (int i = 0; i < 20000; ++i) directions.push_back(random_direction(rng));
  for (const Vec3& d : std::vector<Vec3>{{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                                         {1, 1, 0}, {1, 0, 1}, {0, -1, 1}, {1, 1, 1}, {-1, -1, 1}, {1e-9, 0, 1},
                                         {0, 1e-9, -1}, {1e-7, 0.3, 1}, {-1e-12, 0.2, 1}})
    directions.push_back(normalized(d));
  for (EnvironmentLayout layout : kLayouts) {
    const Size s = size_of(layout, 64);
    double worst = 0;
    for (const Vec3& d : directions) {
      if (layout == EnvironmentLayout::MirrorBall && angle_between(d, {0, 0, -1}) < 1e-4) continue;  // see below
      const Vec2 p = environment_direction_pixel(layout, s.width, s.height, d);
      const std::optional<Vec3> back = environment_pixel_direction(layout, s.width, s.height, p[0], p[1]);
      ASSERT_TRUE(back.has_value()) << environment_layout_name(layout) << " " << d[0] << "," << d[1] << "," << d[2];
      worst = std::max(worst, angle_between(d, *back));
    }
    std::printf("%s: direction -> pixel -> direction worst %.3g rad\n", std::string(environment_layout_name(layout)).c_str(), worst);
    EXPECT_LT(worst, 1e-12) << environment_layout_name(layout);
  }
  // Mirror ball at -z: the rim compresses the whole back hemisphere's last sliver into a zero-width
  // band, so the error grows like eps / (angle from -z): for 1e-6 rad it is still below 1e-9.
  const Size s = size_of(EnvironmentLayout::MirrorBall, 64);
  for (double a : {1e-2, 1e-4, 1e-6}) {
    const Vec3 d{std::sin(a), 0, -std::cos(a)};
    const Vec2 p = environment_direction_pixel(EnvironmentLayout::MirrorBall, s.width, s.height, d);
    const auto back = environment_pixel_direction(EnvironmentLayout::MirrorBall, s.width, s.height, p[0], p[1]);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT(angle_between(d, *back), 1e-9) << a;
  }
}

TEST(EnvironmentLayout, PixelDirectionPixelRoundTripOverValidTexels) {
  // Every valid texel centre maps to a direction and back to itself; worst error printed. Bound
  // 1e-9 px: pixel <-> angle factors are at most ~N, so double rounding gives ~1e-13 px, except the
  // mirror ball's outermost texels where dr/dtheta = cos(theta/2) / 2 ~ sqrt(1 - r^2) magnifies
  // direction rounding by 1 / sqrt(1 - r^2) <= sqrt(N) (still far below 1e-9).
  for (EnvironmentLayout layout : kLayouts) {
    for (int n : {1, 2, 5, 64}) {
      const Size s = size_of(layout, n);
      double worst = 0;
      int valid = 0;
      for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
          const auto d = environment_pixel_direction(layout, s.width, s.height, x, y);
          EXPECT_EQ(d.has_value(), environment_texel_valid(layout, s.width, s.height, x, y));
          if (!d) continue;
          ++valid;
          EXPECT_NEAR(norm(*d), 1, 1e-15);
          const Vec2 p = environment_direction_pixel(layout, s.width, s.height, *d);
          worst = std::max({worst, std::abs(p[0] - x), std::abs(p[1] - y)});
        }
      if (n == 64)
        std::printf("%s %dx%d: pixel -> direction -> pixel worst %.3g px over %d texels\n",
                    std::string(environment_layout_name(layout)).c_str(), s.width, s.height, worst, valid);
      EXPECT_LT(worst, 1e-9) << environment_layout_name(layout) << " n=" << n;
      EXPECT_GT(valid, 0);
    }
  }
}

TEST(EnvironmentLayout, ContinuityAcrossCubeEdgesAndTheEquirectSeam) {
  // Directions on both sides of each of the cube's 12 edges (1e-9 rad apart) land on pixels on
  // the border of their own face; evaluated back from those pixels they are 1e-9 rad apart, i.e.
  // the map is continuous across every edge, including those not adjacent in the image.
  const int F = 16;
  const Size s{3 * F, 4 * F};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> t(-0.99, 0.99);
  int edges = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int s1 : {-1, 1})
      for (int s2 : {-1, 1}) {
        // Edge along `axis`, at the other two axes = s1, s2.
        const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
        for (int k = 0; k < 20; ++k) {
          Vec3 on_edge{};
          on_edge[axis] = t(rng);
          on_edge[a1] = s1;
          on_edge[a2] = s2;
          Vec3 into1 = on_edge, into2 = on_edge;
          into1[a2] *= 1 - 1e-9;  // |a1| largest: face a1
          into2[a1] *= 1 - 1e-9;  // face a2
          const Vec2 p1 = environment_direction_pixel(EnvironmentLayout::CubeCross, s.width, s.height, normalized(into1));
          const Vec2 p2 = environment_direction_pixel(EnvironmentLayout::CubeCross, s.width, s.height, normalized(into2));
          const auto d1 = environment_pixel_direction(EnvironmentLayout::CubeCross, s.width, s.height, p1[0], p1[1]);
          const auto d2 = environment_pixel_direction(EnvironmentLayout::CubeCross, s.width, s.height, p2[0], p2[1]);
          ASSERT_TRUE(d1 && d2);
          EXPECT_LT(angle_between(*d1, *d2), 1e-8);
          EXPECT_LT(angle_between(*d1, normalized(on_edge)), 1e-8);
          // Each pixel lies on its face square's border (within 1e-6 px).
          for (const Vec2& p : {p1, p2}) {
            const double fx = (p[0] + 0.5) / F, fy = (p[1] + 0.5) / F;
            const double to_border = std::min({std::abs(fx - std::round(fx)), std::abs(fy - std::round(fy))});
            EXPECT_LT(to_border * F, 1e-6);
          }
        }
        ++edges;
      }
  EXPECT_EQ(edges, 12);
  // Pixels just either side of the image seams between neighbouring faces.
  for (const auto& [a, b] : std::vector<std::pair<Vec2, Vec2>>{{{F - 0.5 - 1e-9, 20}, {F - 0.5 + 1e-9, 20}},
                                                              {{2 * F - 0.5 - 1e-9, 20}, {2 * F - 0.5 + 1e-9, 20}},
                                                              {{20, F - 0.5 - 1e-9}, {20, F - 0.5 + 1e-9}},
                                                              {{20, 2 * F - 0.5 - 1e-9}, {20, 2 * F - 0.5 + 1e-9}},
                                                              {{20, 3 * F - 0.5 - 1e-9}, {20, 3 * F - 0.5 + 1e-9}}}) {
    const auto da = environment_pixel_direction(EnvironmentLayout::CubeCross, s.width, s.height, a[0], a[1]);
    const auto db = environment_pixel_direction(EnvironmentLayout::CubeCross, s.width, s.height, b[0], b[1]);
    ASSERT_TRUE(da && db);
    EXPECT_LT(angle_between(*da, *db), 1e-8);
  }
  // Equirect: the left and right edges are the same meridian (back).
  for (double py : {0.0, 10.3, 31.5, 63.0}) {
    const auto left = environment_pixel_direction(EnvironmentLayout::Equirectangular, 128, 64, -0.5 + 1e-9, py);
    const auto right = environment_pixel_direction(EnvironmentLayout::Equirectangular, 128, 64, 127.5 - 1e-9, py);
    ASSERT_TRUE(left && right);
    EXPECT_LT(angle_between(*left, *right), 1e-9);
  }
  // Directions just either side of the back meridian map to the two image edges.
  const Vec2 l = environment_direction_pixel(EnvironmentLayout::Equirectangular, 128, 64, normalized({-1e-9, 0.2, 1}));
  const Vec2 r = environment_direction_pixel(EnvironmentLayout::Equirectangular, 128, 64, normalized({1e-9, 0.2, 1}));
  EXPECT_NEAR(l[0], -0.5, 1e-6);
  EXPECT_NEAR(r[0], 127.5, 1e-6);
}

TEST(EnvironmentLayout, DimensionChecks) {
  for (EnvironmentLayout layout : kLayouts)
    for (int n : {1, 3, 64}) {
      const Size s = size_of(layout, n);
      EXPECT_NO_THROW(check_environment_dimensions(layout, s.width, s.height, "probe.hdr"));
    }
  const auto message = [](EnvironmentLayout layout, int w, int h) {
    return hdr_test::asset_error_message([&] { check_environment_dimensions(layout, w, h, "probe.hdr"); });
  };
  EXPECT_EQ(message(EnvironmentLayout::AngularMap, 64, 63), "probe.hdr: layout \"angular\" needs a square image, but it is 64 x 63");
  EXPECT_NE(message(EnvironmentLayout::MirrorBall, 0, 0).find("probe.hdr: layout \"mirror-ball\" needs a square image"), std::string::npos);
  EXPECT_EQ(message(EnvironmentLayout::Equirectangular, 100, 100),
            "probe.hdr: layout \"equirect\" needs an image twice as wide as tall (2H x H), but it is 100 x 100");
  EXPECT_NE(message(EnvironmentLayout::Equirectangular, 0, 0).find("equirect"), std::string::npos);
  EXPECT_EQ(message(EnvironmentLayout::CubeCross, 64, 48),
            "probe.hdr: layout \"cube-cross\" needs 3 faces across and 4 down (3F x 4F, F >= 1), but it is 64 x 48");
  EXPECT_NE(message(EnvironmentLayout::CubeCross, 4, 4).find("cube-cross"), std::string::npos);
  EXPECT_NE(message(EnvironmentLayout::CubeCross, 0, 0).find("cube-cross"), std::string::npos);
}

}  // namespace
}  // namespace arpipe
