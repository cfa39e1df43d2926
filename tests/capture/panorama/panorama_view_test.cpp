// The panorama's view: its turn against the stated convention, the background lookup against a
// double-precision remap at every latitude and along the seam, and the looked-up background
// against an image whose every texel is a known function of its direction.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "capture/panorama/equirect_image.h"
#include "capture/panorama/panorama_view.h"
#include "core/environment/environment_layout.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

Vec3 column(const Mat3& m, size_t c) { return {m[0][c], m[1][c], m[2][c]}; }

void expect_near(const Vec3& a, const Vec3& b, double tolerance) {
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tolerance) << "component " << i;
}

TEST(PanoramaView, TurnsAsStated) {
  // Panorama frame: x right, y up, -z the image's centre; camera columns: right, down, forward.
  const Mat3 ahead = panorama_view_rotation(0, 0);
  expect_near(column(ahead, 0), {1, 0, 0}, 1e-15);
  expect_near(column(ahead, 1), {0, -1, 0}, 1e-15);
  expect_near(column(ahead, 2), {0, 0, -1}, 1e-15);
  const Mat3 right = panorama_view_rotation(90 * kDeg, 0);  // turning right looks along +x
  expect_near(column(right, 2), {1, 0, 0}, 1e-15);
  expect_near(column(right, 1), {0, -1, 0}, 1e-15);
  const Mat3 zenith = panorama_view_rotation(0, 90 * kDeg);  // pitch 90: up, the image's top beyond
  expect_near(column(zenith, 2), {0, 1, 0}, 1e-15);
  expect_near(column(zenith, 1), {0, 0, -1}, 1e-15);  // the camera's down points at the centre
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < 100; ++i) {
    const Mat3 R = panorama_view_rotation(angle(rng), angle(rng) / 2);
    EXPECT_NEAR(dot(cross(column(R, 0), column(R, 1)), column(R, 2)), 1.0, 1e-12);  // a rotation
    for (size_t a = 0; a < 3; ++a)
      for (size_t b = 0; b < 3; ++b) EXPECT_NEAR(dot(column(R, a), column(R, b)), a == b ? 1.0 : 0.0, 1e-12);
  }
  // Looking right moves right in the image: the centre pixel's column grows with the yaw.
  const auto centre_column = [](double yaw) {
    return environment_direction_pixel(EnvironmentLayout::Equirectangular, 4096, 2048,
                                       column(panorama_view_rotation(yaw, 0), 2))[0];
  };
  EXPECT_NEAR(centre_column(0), 2047.5, 1e-9);
  EXPECT_NEAR(centre_column(90 * kDeg), 3071.5, 1e-9);
}

// The angle (in level-0 texels, pi / height) between the directions of two panorama positions.
double texels_apart(const std::array<float, 2>& a, const Vec2& b, int width, int height) {
  const auto d = [&](double u, double v) {
    return *environment_pixel_direction(EnvironmentLayout::Equirectangular, width, height, u, v);
  };
  const Vec3 da = d(a[0], a[1]), db = d(b[0], b[1]);
  return std::atan2(norm(cross(da, db)), dot(da, db)) / (kPi / height);
}

// A 1080p view of a 4096 x 2048 panorama, turned to the seam and to both poles among others: the
// position each pixel looks up (float) against the same remap in double (mrcal's unprojection,
// the rotation and environment_direction_pixel), per band of 10 degrees of latitude. Directly, and
// from the yaw-free table that a sweep's frames use (made by two frames at another yaw, the same
// tilt), which must meet the same bars.
void expect_lookup_agrees_with_double_precision(bool from_table) {
  constexpr int W = 4096, H = 2048;
  EquirectImage panorama(std::vector<uint8_t>(size_t(W) * H * 3, 128), W, H, "grey");
  const double fx = 0.5 * 1920 / std::tan(45 * kDeg);
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(fx, fx, 959.5, 539.5, 1920, 1080));
  const PanoramaView view(camera);
  std::array<double, 19> sum{}, most{};
  std::array<int, 19> count{};
  std::vector<uint8_t> picture(size_t(1920) * 1080 * 3);
  for (const auto& [yaw, pitch] : std::vector<std::pair<double, double>>{
           {0, 0}, {180, 0}, {-179.9, 30}, {180, -45}, {33, 89.9}, {0, 90}, {-120, -90}, {77, -60}, {250, 60}}) {
    const Mat3 R = panorama_view_rotation(yaw * kDeg, pitch * kDeg);
    if (from_table) {
      const Mat3 before = panorama_view_rotation((yaw - 97) * kDeg, pitch * kDeg);
      view.render(panorama, before, picture.data(), 1920 * 3);
      view.render(panorama, before, picture.data(), 1920 * 3);
      // (Straight up or down the view's axis does not define the yaw: the table may or may not match.)
      if (std::abs(pitch) < 90) {
        EXPECT_TRUE(view.uses_yaw_table(panorama, R)) << "yaw " << yaw << " pitch " << pitch;
      }
    }
    std::vector<std::array<float, 2>> positions;
    view.lookup_positions(panorama, R, positions);
    for (int y = 0; y < 1080; y += 3)
      for (int x = 0; x < 1920; x += 3) {
        const Vec3 ray = normalized(*camera->unproject({double(x), double(y)}));
        const Vec3 d = mat_mul(R, ray);
        const Vec2 truth = environment_direction_pixel(EnvironmentLayout::Equirectangular, W, H, d);
        const double error = texels_apart(positions[size_t(y) * 1920 + size_t(x)], truth, W, H);
        const size_t band = size_t(std::lround((std::asin(std::clamp(d[1], -1.0, 1.0)) / kDeg + 90) / 10));
        sum[band] += error;
        most[band] = std::max(most[band], error);
        ++count[band];
      }
  }
  for (size_t band = 0; band < 19; ++band) {
    ASSERT_GT(count[band], 100) << "latitude " << int(band) * 10 - 90 << " not reached";
    EXPECT_LE(sum[band] / count[band], 0.1) << "mean, latitude " << int(band) * 10 - 90;
    EXPECT_LE(most[band], 0.5) << "max, latitude " << int(band) * 10 - 90;
  }
}

TEST(PanoramaView, LookupAgreesWithDoublePrecisionAtEveryLatitudeAndAlongTheSeam) {
  expect_lookup_agrees_with_double_precision(false);
}

TEST(PanoramaView, TheSweepsYawFreeTableAgreesWithDoublePrecisionToo) { expect_lookup_agrees_with_double_precision(true); }

// A smooth colour field over the sphere: each channel a different low-order function of the
// direction, between 20 and 235.
std::array<double, 3> field(const Vec3& d) {
  return {128 + 100 * d[0], 128 + 60 * d[1] + 40 * d[0] * d[2], 128 + 90 * d[2] * d[1] + 10 * d[0]};
}

TEST(PanoramaView, BackgroundIsTheSceneAlongEachRayAcrossTheSeamAndThePoles) {
  constexpr int W = 2048, H = 1024;
  std::vector<uint8_t> rgb(size_t(W) * H * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const Vec3 d = *environment_pixel_direction(EnvironmentLayout::Equirectangular, W, H, x, y);
      const std::array<double, 3> c = field(d);
      for (size_t k = 0; k < 3; ++k) rgb[(size_t(y) * W + size_t(x)) * 3 + k] = uint8_t(std::lround(c[k]));
    }
  EquirectImage panorama(std::move(rgb), W, H, "field");
  const double fx = 0.5 * 640 / std::tan(50 * kDeg);
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(fx, fx, 319.5, 239.5, 640, 480));
  const PanoramaView view(camera);
  std::vector<uint8_t> out(640 * 480 * 3);
  for (const auto& [yaw, pitch] : std::vector<std::pair<double, double>>{{180, 0}, {10, 90}, {-100, -90}, {45, 70}}) {
    const Mat3 R = panorama_view_rotation(yaw * kDeg, pitch * kDeg);
    view.render(panorama, R, out.data(), 640 * 3);
    double worst = 0, sum = 0;
    for (int y = 0; y < 480; ++y)
      for (int x = 0; x < 640; ++x) {
        const std::array<double, 3> truth = field(mat_mul(R, normalized(*camera->unproject({double(x), double(y)}))));
        for (size_t k = 0; k < 3; ++k) {
          const double e = std::abs(out[(size_t(y) * 640 + size_t(x)) * 3 + k] - truth[k]);
          worst = std::max(worst, e);
          sum += e;
        }
      }
    // The field changes by under 0.4 levels a texel: bilinear taps and the pyramid's means stay
    // within rounding (0.5 in the image, 0.5 in the output) and a level's blur.
    EXPECT_LE(worst, 2.0) << "yaw " << yaw << ", pitch " << pitch;
    EXPECT_LE(sum / (640 * 480 * 3), 0.6) << "yaw " << yaw << ", pitch " << pitch;
  }
}

TEST(PanoramaView, FinePatternTowardsThePoleAveragesInsteadOfAliasing) {
  // Stripes 4 texels wide (black and white columns, 256 periods round): towards the pole a view
  // pixel spans several periods across, and must show their mean (127.5), not a stray stripe as a
  // sample at one point would (127.5 off).
  constexpr int W = 2048, H = 1024;
  std::vector<uint8_t> rgb(size_t(W) * H * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int k = 0; k < 3; ++k) rgb[(size_t(y) * W + size_t(x)) * 3 + size_t(k)] = (x / 4) % 2 ? 255 : 0;
  EquirectImage panorama(std::move(rgb), W, H, "stripes");
  const double fx = 0.5 * 320 / std::tan(45 * kDeg);
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(fx, fx, 159.5, 119.5, 320, 240));
  const PanoramaView view(camera);
  std::vector<uint8_t> out(320 * 240 * 3);
  const Mat3 R = panorama_view_rotation(0, 90 * kDeg);
  view.render(panorama, R, out.data(), 320 * 3);
  double sum = 0, worst = 0;
  int count = 0;
  for (int y = 0; y < 240; ++y)
    for (int x = 0; x < 320; ++x) {
      const Vec3 d = mat_mul(R, normalized(*camera->unproject({double(x), double(y)})));
      if (d[1] < std::sin(84 * kDeg)) continue;  // the cap where a pixel spans 3 periods or more
      const double off = std::abs(out[(size_t(y) * 320 + size_t(x)) * 3] - 127.5);
      sum += off;
      worst = std::max(worst, off);
      ++count;
    }
  ASSERT_GT(count, 500);
  std::cout << "polar cap: mean " << sum / count << ", worst " << worst << " levels off the stripes' mean\n";
  EXPECT_LE(sum / count, 16.0);
  EXPECT_LE(worst, 64.0);
}

TEST(PanoramaView, PyramidBuiltOnDemandGivesTheSamePictureAsTheWholePyramid) {
  // The lookup builds only the levels levels_needed bounds for the view's turn: every pixel must get
  // the same bytes as with every level built, at the horizon, towards and at both poles, for views
  // that magnify and one that minifies 4 times; and a view that never minifies builds none.
  constexpr int W = 1024, H = 512;
  std::vector<uint8_t> rgb(size_t(W) * H * 3);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> byte(0, 255);
  for (uint8_t& b : rgb) b = uint8_t(byte(rng));
  EquirectImage whole(rgb, W, H, "noise");
  whole.build_levels(whole.levels());
  ASSERT_EQ(whole.built_levels(), 7);  // 512 down to 8
  struct View {
    int width, height;
    double hfov_deg;
  };
  for (const View v : {View{640, 480, 60}, View{64, 48, 120}, View{160, 120, 170}}) {
    const double fx = 0.5 * v.width / std::tan(0.5 * v.hfov_deg * kDeg);
    const auto camera = std::make_shared<const CameraModel>(
        CameraModel::pinhole(fx, fx, 0.5 * (v.width - 1), 0.5 * (v.height - 1), v.width, v.height));
    // Each lookup on a view of its own: the first frame of a tilt is looked up directly, the next
    // from the yaw-free table (both paths, each against itself).
    for (const double pitch : {0.0, 30.0, 60.0, 80.0, 89.0, 90.0, -45.0, -90.0})
      for (const int frames : {1, 2}) {
        const Mat3 R = panorama_view_rotation(1.3, pitch * kDeg);
        EquirectImage lazy(rgb, W, H, "noise");
        std::vector<uint8_t> a(size_t(v.width) * size_t(v.height) * 3), b(a.size());
        const PanoramaView on_lazy(camera), on_whole(camera);
        for (int f = 0; f < frames; ++f) {
          on_lazy.render(lazy, R, a.data(), size_t(v.width) * 3);
          on_whole.render(whole, R, b.data(), size_t(v.width) * 3);
        }
        EXPECT_EQ(a, b) << v.width << "x" << v.height << ", pitch " << pitch << ", frame " << frames << ": "
                        << lazy.built_levels() << " levels built";
        if (v.width == 640 && std::abs(pitch) <= 30) {
          EXPECT_EQ(lazy.built_levels(), 1) << "pitch " << pitch;
        }
      }
  }
}

}  // namespace
}  // namespace arpipe
