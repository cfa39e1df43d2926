// Analytic checks of the probe building blocks: the mirror reflection, the sphere's image region,
// the camera response and the linear patch (the SH maths are tested in tests/sh).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "core/image/camera_response.h"
#include "core/image/pixel_convert.h"
#include "core/image/srgb.h"
#include "core/light/linear_patch.h"
#include "core/probe/probe_sphere.h"
#include "core/probe/brightest_components.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ProbeReflection, AnalyticCases) {
  const Vec3 r = reflect(normalized(Vec3{1, -1, 0}), {0, 1, 0});
  EXPECT_NEAR(r[0], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(r[1], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(r[2], 0, 1e-12);
  // A far camera on -y looks along +y at the point of a mirror ball whose normal is (0, -1, 1)/sqrt 2:
  // the 45-degree facet sends the view ray straight up, so the light is at +z.
  const ProbeSphere mirror{ProbeSphere::Kind::Mirror, {0, 0, 0}, 1.0, 0.9};
  const Vec3 n = normalized(Vec3{0, -1, 1});
  const Vec3 l = highlight_light_direction(mirror, {0, -1e7, std::sqrt(0.5)}, n);
  EXPECT_NEAR(l[0], 0, 1e-9);
  EXPECT_NEAR(l[1], 0, 1e-6);
  EXPECT_NEAR(l[2], 1, 1e-9);
  // Facing the camera: the light is behind the camera (the ray comes straight back).
  const Vec3 back = highlight_light_direction(mirror, {0, 0, 5}, {0, 0, 1});
  EXPECT_NEAR(back[2], 1, 1e-12);
  // The seed's printed formula -2 (c_i.n_s) n - c_i is not this: with n the point (0, 0, 1) it gives
  // 2 (0,0,1) - (0,0,-1) = (0, 0, 3), not a unit vector; we use reflect(). A diffuse sphere's
  // brightest point's normal is the light direction.
  const ProbeSphere diffuse{ProbeSphere::Kind::Diffuse, {0, 0, 0}, 1.0, 0.7};
  const Vec3 d = highlight_light_direction(diffuse, {0, -5, 0}, n);
  EXPECT_NEAR(dot(d, n), 1, 1e-12);
}

TEST(ProbeRegion, PinholeSphereStraightAhead) {
  const CameraModel cam = CameraModel::pinhole(500, 500, 320, 240, 640, 480);
  const ProbeSphere s{ProbeSphere::Kind::Mirror, {0, 0, 1}, 0.1, 0.9};
  PixelRayCache rays;
  ProbeRegion r;
  ASSERT_TRUE(compute_probe_region(s, cam, SE3::identity(), rays, r));
  // The silhouette's radius: f tan(asin(r / d)) = 500 * 0.1 / sqrt(0.99).
  const double radius = 500 * 0.1 / std::sqrt(0.99);
  EXPECT_NEAR(r.radius_px, radius, 0.05);
  EXPECT_EQ(r.rim_in_image, 1.0);
  const double pixels = double(r.hits.size()) + r.rim_pixels;
  EXPECT_NEAR(pixels, kPi * radius * radius, 2 * kPi * radius * 0.6);
  // Rim pixels: a ring about 1 px wide.
  EXPECT_NEAR(r.rim_pixels, 2 * kPi * radius, 0.3 * 2 * kPi * radius);
  const int centre = r.hit_at(320, 240);
  ASSERT_GE(centre, 0);
  EXPECT_NEAR(r.hits[size_t(centre)].normal_world[2], -1, 1e-9);
  EXPECT_NEAR(r.hits[size_t(centre)].distance_m, 0.9, 1e-9);
  // Behind the camera: no region.
  ProbeRegion behind;
  EXPECT_FALSE(compute_probe_region({ProbeSphere::Kind::Mirror, {0, 0, -1}, 0.1, 0.9}, cam, SE3::identity(), rays, behind));
  EXPECT_FALSE(behind.in_front);
  // Centred on the left border: half the rim in view.
  ProbeRegion half;
  ASSERT_TRUE(compute_probe_region({ProbeSphere::Kind::Mirror, {-320.0 / 500, 0, 1}, 0.1, 0.9}, cam, SE3::identity(),
                                   rays, half));
  EXPECT_NEAR(half.rim_in_image, 0.5, 0.05);
}

// Through a distorted lens every analysed pixel's hit point projects back onto that pixel: the rays
// are the lens's true rays.
TEST(ProbeRegion, DistortedLensHitsProjectBack) {
  const CameraModel cam("LENSMODEL_OPENCV4", {520, 520, 323, 237, -0.05, 0.012, 0.0004, -0.0003}, 640, 480);
  const SE3 T_cam_world = SE3::from_rt({0.1, -0.2, 0.05}, {0.02, -0.01, 0.3});
  const ProbeSphere s{ProbeSphere::Kind::Diffuse, T_cam_world.inverse() * Vec3{0.2, 0.15, 0.6}, 0.04, 0.7};
  PixelRayCache rays;
  ProbeRegion r;
  ASSERT_TRUE(compute_probe_region(s, cam, T_cam_world, rays, r));
  ASSERT_GT(r.hits.size(), 500u);
  double worst = 0;
  for (const ProbeHit& h : r.hits) {
    const Vec3 p = s.center_world + s.radius_m * h.normal_world;
    const auto px = cam.project(T_cam_world * p);
    ASSERT_TRUE(px);
    worst = std::max(worst, norm(*px - Vec2{double(h.x), double(h.y)}));
  }
  EXPECT_LT(worst, 1e-3);  // float rays: ~1e-7 rad at 520 px/rad
}

TEST(ProbeCameraResponse, ParseAndDecode) {
  EXPECT_EQ(CameraResponse::parse("srgb", "t").kind(), CameraResponse::Kind::Srgb);
  EXPECT_EQ(CameraResponse::parse("linear", "t").kind(), CameraResponse::Kind::Linear);
  const CameraResponse g = CameraResponse::parse("gamma:2.2", "t");
  EXPECT_NEAR(g.decode8(128), std::pow(128 / 255.0, 2.2), 1e-6);
  for (const char* bad : {"gamma:", "gamma:0", "gamma:-1", "gamma:x", "SRGB", ""}) {
    try {
      (void)CameraResponse::parse(bad, "light.camera_response");
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("light.camera_response"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find(std::string("\"") + bad + "\""), std::string::npos);
    }
  }
  const CameraResponse s;
  EXPECT_EQ(s.decode8(0), 0.0f);
  EXPECT_EQ(s.decode8(255), 1.0f);
  EXPECT_NEAR(s.decode8(128), srgb_decode(128 / 255.0), 1e-7);
  EXPECT_TRUE(CameraResponse::clipped(250));
  EXPECT_FALSE(CameraResponse::clipped(249));
}

// A rect with odd corners of a YUYV and an NV12 frame decodes to the same values as to_rgb24 of
// the whole frame, divided by exposure x gain.
TEST(ProbeLinearPatch, MatchesWholeFrameConversion) {
  const int w = 64, h = 48;
  std::vector<uint8_t> rgb(size_t(w * h * 3));
  std::mt19937 rng(7);
  for (auto& v : rgb) v = uint8_t(rng() % 256);
  for (PixelFormat f : {PixelFormat::RGB24, PixelFormat::YUYV, PixelFormat::NV12, PixelFormat::GREY}) {
    Frame frame = from_rgb24(rgb.data(), w, h, f);
    frame.meta.exposure_ns = 8'000'000;
    frame.meta.analogue_gain = 2;
    frame.meta.digital_gain = 1.5;
    std::vector<uint8_t> full;
    to_rgb24(frame, full);
    LinearPatch p;
    const CameraResponse resp;
    ASSERT_TRUE(decode_linear_patch(frame, {13, 7, 21, 15}, resp, p));
    const double scale = 1 / (0.008 * 3.0);
    for (int y = 7; y < 22; ++y)
      for (int x = 13; x < 34; ++x)
        for (int c = 0; c < 3; ++c) {
          const uint8_t v = full[size_t((y * w + x) * 3 + c)];
          ASSERT_NEAR(p.at(x, y)[c], resp.decode8(v) * scale, 1e-3) << pixel_format_name(f) << " " << x << "," << y;
        }
    // Clipped where any channel is >= 250.
    for (int y = 7; y < 22; ++y)
      for (int x = 13; x < 34; ++x) {
        const uint8_t* q = &full[size_t((y * w + x) * 3)];
        EXPECT_EQ(p.clipped_at(x, y), std::max({q[0], q[1], q[2]}) >= 250);
      }
    frame.meta.exposure_ns = 0;
    EXPECT_FALSE(decode_linear_patch(frame, {0, 0, 8, 8}, resp, p));
  }
}

}  // namespace
}  // namespace arpipe
