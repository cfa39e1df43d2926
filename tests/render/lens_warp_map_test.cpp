// Tests of the lens warp map (render.lens = "map") against mrcal: 3D points drawn with the pinhole
// canvas and carried back through the inverted map land where CameraModel::project (mrcal) puts
// them, for a strongly distorted OPENCV8 lens and a splined model; the canvas holds every ray;
// pinhole lenses need no warp; lenses a pinhole canvas cannot hold are refused by name.
#include "render/lens/lens_warp_map.h"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <random>

#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

constexpr int kWidth = 640, kHeight = 480;

// Strong barrel distortion: the corners' rays are 54 degrees off axis, and the lens moves them
// about 150 px inwards. (k1 = -0.35, k2 = 0.15, k3 = -0.03 would fold over before the corners:
// see FoldingLensIsRefused.)
CameraModel strong_opencv8() {
  return CameraModel("LENSMODEL_OPENCV8",
                     {400, 400, 322.3, 236.8, -0.30, 0.10, 0.001, -0.0008, -0.01, 0.0, 0.0, 0.0}, kWidth, kHeight);
}

// A splined stereographic lens with known, smooth control values (mrcal adds the splines to the
// stereographic projection); corners 67 degrees off axis.
CameraModel splined() {
  std::vector<double> intrinsics{300, 302, 318.2, 241.6};
  for (int i = 0; i < 16 * 12; ++i) {
    const int x = i % 16, y = i / 16;
    intrinsics.push_back(0.015 * std::sin(0.4 * x + 0.2 * y));  // delta of the x coordinate
    intrinsics.push_back(-0.012 * std::cos(0.3 * x - 0.5 * y));  // delta of the y coordinate
  }
  return CameraModel("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=150", intrinsics, kWidth,
                     kHeight);
}

// Maps of the strong lens, built once per canvas scale (each build unprojects every pixel).
const LensWarpMap& strong_map(double scale) {
  static std::map<double, std::unique_ptr<LensWarpMap>> maps;
  std::unique_ptr<LensWarpMap>& map = maps[scale];
  if (!map) map = std::make_unique<LensWarpMap>(strong_opencv8(), scale);
  return *map;
}

// The map between pixel centres, bilinear as the GPU's interpolation would be if it sampled it.
Vec2 map_at(const LensWarpMap& map, const Vec2& q, Vec2* d_dx = nullptr, Vec2* d_dy = nullptr) {
  const int x0 = std::clamp(int(std::floor(q[0])), 0, map.width() - 2);
  const int y0 = std::clamp(int(std::floor(q[1])), 0, map.height() - 2);
  const double fx = q[0] - x0, fy = q[1] - y0;
  const Vec2 a = map.at(x0, y0), b = map.at(x0 + 1, y0), c = map.at(x0, y0 + 1), d = map.at(x0 + 1, y0 + 1);
  Vec2 out;
  for (size_t k = 0; k < 2; ++k) {
    out[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]);
    if (d_dx) (*d_dx)[k] = (1 - fy) * (b[k] - a[k]) + fy * (d[k] - c[k]);
    if (d_dy) (*d_dy)[k] = (1 - fx) * (c[k] - a[k]) + fx * (d[k] - b[k]);
  }
  return out;
}

// The lens pixel whose map value is `canvas_xy`: Newton on the bilinear map from the image centre.
Vec2 invert_map(const LensWarpMap& map, const Vec2& canvas_xy) {
  Vec2 q{map.width() / 2.0, map.height() / 2.0};
  for (int iteration = 0; iteration < 100; ++iteration) {
    Vec2 d_dx, d_dy;
    const Vec2 value = map_at(map, q, &d_dx, &d_dy);
    const double rx = canvas_xy[0] - value[0], ry = canvas_xy[1] - value[1];
    const double det = d_dx[0] * d_dy[1] - d_dy[0] * d_dx[1];
    const Vec2 step{(d_dy[1] * rx - d_dy[0] * ry) / det, (-d_dx[1] * rx + d_dx[0] * ry) / det};
    q = {q[0] + step[0], q[1] + step[1]};
    if (std::hypot(step[0], step[1]) < 1e-9) break;
  }
  return q;
}

// Points in front of the camera whose images (by mrcal's forward projection) cover the whole
// image, corners included: random rays over a generous cone, kept when they land in the image,
// plus the rays of the four corner pixels. Rays outside the canvas are left out: they lie beyond
// the fold of a polynomial lens, where mrcal's projection comes back into the image although no
// such ray reaches the sensor (the canvas holds every ray that does: CanvasHoldsEveryRay...).
std::vector<Vec3> points_over_the_image(const CameraModel& model, const PinholeCanvas& canvas) {
  std::mt19937 random(4242);
  std::uniform_real_distribution<double> slope(-2.5, 2.5), depth(0.2, 10.0);
  std::vector<Vec3> points;
  for (const Vec2& corner : {Vec2{0, 0}, Vec2{kWidth - 1.0, 0}, Vec2{0, kHeight - 1.0}, Vec2{kWidth - 1.0, kHeight - 1.0}})
    points.push_back(3.0 * *model.unproject(corner));
  while (points.size() < 3000) {
    const double z = depth(random);
    const Vec3 p{slope(random) * z, slope(random) * z, z};
    const double u = canvas.fx * p[0] / p[2] + canvas.cx, v = canvas.fy * p[1] / p[2] + canvas.cy;
    if (u < 0 || v < 0 || u > canvas.width - 1 || v > canvas.height - 1) continue;
    const std::optional<Vec2> q = model.project(p);
    if (q && (*q)[0] >= 0 && (*q)[0] <= kWidth - 1 && (*q)[1] >= 0 && (*q)[1] <= kHeight - 1) points.push_back(p);
  }
  return points;
}

void expect_map_matches_mrcal(const CameraModel& model, double canvas_scale = 1.0) {
  const auto start = std::chrono::steady_clock::now();
  const LensWarpMap map(model, canvas_scale);
  const double build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(map.identity());
  const PinholeCanvas& canvas = map.canvas();
  EXPECT_EQ(canvas.fx, canvas_scale * model.fx());
  EXPECT_EQ(canvas.fy, canvas_scale * model.fy());
  double worst = 0, sum = 0;
  const std::vector<Vec3> points = points_over_the_image(model, canvas);
  for (const Vec3& p : points) {
    const Vec2 truth = *model.project(p);
    // Where the pinhole canvas draws the point, then back through the map to the lens image.
    const Vec2 on_canvas{canvas.fx * p[0] / p[2] + canvas.cx, canvas.fy * p[1] / p[2] + canvas.cy};
    const Vec2 q = invert_map(map, on_canvas);
    const double error = std::hypot(q[0] - truth[0], q[1] - truth[1]);
    worst = std::max(worst, error);
    sum += error;
    // 0.01 px: the map is exact at pixel centres up to float storage (~1e-4 px on a 1000 px
    // canvas); between centres bilinear interpolation errs by h^2/8 times the map's second
    // derivative, ~1e-3 px for this lens. A wrong core, shift, scale or pixel-centre convention
    // costs 0.5 px or more.
    ASSERT_LT(error, 0.01) << model.lensmodel() << " point (" << p[0] << ", " << p[1] << ", " << p[2] << "): map ("
                           << q[0] << ", " << q[1] << "), mrcal (" << truth[0] << ", " << truth[1] << ")";
  }
  std::cout << model.lensmodel() << " at canvas scale " << canvas_scale << ": canvas " << canvas.width << "x"
            << canvas.height << ", map built in " << build_ms << " ms; map vs mrcal over " << points.size()
            << " points: max " << worst << " px, mean "
            << sum / double(points.size()) << " px\n";
}

TEST(LensWarpMap, StrongOpenCv8MatchesMrcalOverTheWholeImage) {
  expect_map_matches_mrcal(strong_opencv8());
  expect_map_matches_mrcal(strong_opencv8(), 1.5);
}

TEST(LensWarpMap, SplinedModelMatchesMrcalOverTheWholeImage) { expect_map_matches_mrcal(splined()); }

// The canvas texels that the warp reads for lens pixel (x, y), as lens_warp_pass.cpp samples:
// 2 x 2 taps a quarter pixel each way along the steps to the neighbouring pixels, each reading
// the 2 x 2 texels around it. Calls visit(texel_x, texel_y) for each.
template <typename Visit>
void for_each_texel_read(const LensWarpMap& map, int x, int y, Visit&& visit) {
  const Vec2 c = map.at(x, y);
  const int dx = x + 1 < map.width() ? 1 : -1, dy = y + 1 < map.height() ? 1 : -1;
  const Vec2 nx = map.at(x + dx, y), ny = map.at(x, y + dy);
  const Vec2 along_x{dx * (nx[0] - c[0]), dx * (nx[1] - c[1])}, along_y{dy * (ny[0] - c[0]), dy * (ny[1] - c[1])};
  for (const double i : {-0.25, 0.25})
    for (const double j : {-0.25, 0.25}) {
      const double u = c[0] + i * along_x[0] + j * along_y[0], v = c[1] + i * along_x[1] + j * along_y[1];
      const int tx = int(std::floor(u)), ty = int(std::floor(v));
      visit(tx, ty);
      visit(tx + 1, ty + 1);
    }
}

TEST(LensWarpMap, CanvasHoldsEveryTexelTheWarpReads) {
  for (const double scale : {1.0, 1.5, 4.0}) {
    const LensWarpMap& map = strong_map(scale);
    const PinholeCanvas& canvas = map.canvas();
    EXPECT_EQ(canvas.fx, scale * 400);
    int min_x = canvas.width, min_y = canvas.height, max_x = -1, max_y = -1;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x)
        for_each_texel_read(map, x, y, [&](int tx, int ty) {
          min_x = std::min(min_x, tx), max_x = std::max(max_x, tx), min_y = std::min(min_y, ty), max_y = std::max(max_y, ty);
        });
    // Inside, with a texel to spare, and no bigger than that needs beyond the slack of the
    // bound on the taps' reach (tap_reach() each side, from the largest step between pixels).
    EXPECT_GE(min_x, 1) << scale;
    EXPECT_GE(min_y, 1) << scale;
    EXPECT_LE(max_x, canvas.width - 2) << scale;
    EXPECT_LE(max_y, canvas.height - 2) << scale;
    const int slack = 2 * int(std::ceil(map.tap_reach()));
    EXPECT_LE(canvas.width, max_x - min_x + 6 + slack) << scale;
    EXPECT_LE(canvas.height, max_y - min_y + 6 + slack) << scale;
  }
  // Barrel distortion: the canvas is wider than the image (the corners' rays need 1.38 focal
  // lengths of pinhole image plane each side, the image edge 0.8).
  EXPECT_GT(strong_map(1.0).canvas().width, kWidth);
}

TEST(LensWarpMap, CanvasRectCoversEveryTexelTheWarpReadsForTheImageRect) {
  for (const double scale : {1.0, 4.0}) {
    const LensWarpMap& map = strong_map(scale);
    for (const PixelRect& rect : {PixelRect{0, 0, 40, 30}, PixelRect{600, 440, 40, 40}, PixelRect{300, 200, 57, 33},
                                  PixelRect{0, 0, kWidth, kHeight}, PixelRect{5, 300, 200, 180}}) {
      const PixelRect canvas_rect = map.canvas_rect_for(rect);
      for (int y = rect.y; y < rect.bottom(); ++y)
        for (int x = rect.x; x < rect.right(); ++x)
          for_each_texel_read(map, x, y, [&](int tx, int ty) {
            ASSERT_TRUE(canvas_rect.contains(tx, ty))
                << "scale " << scale << ": pixel (" << x << ", " << y << ") reads texel (" << tx << ", " << ty
                << "), outside (" << canvas_rect.x << ", " << canvas_rect.y << ", " << canvas_rect.width << ", "
                << canvas_rect.height << ")";
          });
    }
  }
}

TEST(LensWarpMap, PinholeLensIsTheIdentity) {
  const CameraModel pinhole = CameraModel::pinhole(410, 405, 318.7, 241.2, kWidth, kHeight);
  const LensWarpMap map(pinhole);
  EXPECT_TRUE(map.identity());
  EXPECT_TRUE(map.canvas_xy().empty());
  EXPECT_EQ(map.canvas().width, kWidth);
  EXPECT_EQ(map.canvas().height, kHeight);
  EXPECT_EQ(map.canvas().cx, 318.7);
  EXPECT_EQ(map.canvas().cy, 241.2);
  EXPECT_EQ(map.canvas_rect_for(PixelRect{10, 20, 30, 40}), (PixelRect{10, 20, 30, 40}));
  EXPECT_NO_THROW(check_lens_warpable(pinhole));
}

void expect_render_error(const std::function<void()>& call, const std::vector<std::string>& fragments) {
  try {
    call();
    ADD_FAILURE() << "expected RenderError";
  } catch (const RenderError& e) {
    for (const std::string& fragment : fragments)
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "missing \"" << fragment << "\" in " << e.what();
  }
}

TEST(LensWarpMap, LensTooWideForAPinholeCanvasIsRefusedByName) {
  // Stereographic with f = 150 px: pixel (0, 0) is 2 atan(399.3 / 300) = 106.2 degrees off axis.
  const CameraModel fisheye("LENSMODEL_STEREOGRAPHIC", {150, 150, 319.5, 239.5}, kWidth, kHeight);
  const std::vector<std::string> fragments{"LENSMODEL_STEREOGRAPHIC", "106.2 degrees off its axis", "at most 75 degrees",
                                           "render.lens = \"undistort\""};
  expect_render_error([&] { LensWarpMap map(fisheye); }, fragments);
  expect_render_error([&] { check_lens_warpable(fisheye); }, fragments);
  // At f = 300 px the corners are 67 degrees off axis: a canvas holds that.
  EXPECT_NO_THROW(check_lens_warpable(CameraModel("LENSMODEL_STEREOGRAPHIC", {300, 300, 319.5, 239.5}, kWidth, kHeight)));
}

TEST(LensWarpMap, FoldingLensIsRefusedByName) {
  // r (1 - 0.35 r^2 + 0.15 r^4 - 0.03 r^6) peaks at 0.945 near r = 1.5: the corners (r = 1.0 at
  // f = 400 px) are beyond the fold, where no ray reaches.
  const CameraModel folding("LENSMODEL_OPENCV8", {400, 400, 319.5, 239.5, -0.35, 0.15, 0.001, -0.0008, -0.03, 0, 0, 0},
                            kWidth, kHeight);
  expect_render_error([&] { LensWarpMap map(folding); }, {"LENSMODEL_OPENCV8", "pixel (0, 0)", "render.lens = \"map\""});
  expect_render_error([&] { check_lens_warpable(folding); }, {"LENSMODEL_OPENCV8", "render.lens = \"map\""});
}

}  // namespace
}  // namespace arpipe
