// A proxy's tilted face catches a virtual shadow with the light a real face gets: under the
// config's constant ambient (a sky above the ground) a vertical face sees the sky over half its
// view and the lit ground over the other half, so the umbra's ratio is analytic:
// A / (A + D), A = L / 2 + albedo (C l_z + L) / 2, D = C cos(face, light).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;
// The light from -x, 25.8 degrees up: the 6 cm cube at the origin throws its umbra onto the wall's
// -x face (x = 0.06) for |y| < 0.03 and z up to 4.5 cm.
const Vec3 kTowardsLight{-0.9, 0.0, 0.43589};
const Box kCube{{-0.03, -0.03, 0.0}, {0.03, 0.03, 0.06}};
const Box kWall{{0.06, -0.2, 0.0}, {0.08, 0.2, 0.3}};
constexpr double kSky = 0.3, kLight = 1.0;

StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

Config wall_config(double ground_albedo) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.light_direction = kTowardsLight;
  config.render.light_color = {kLight, kLight, kLight};
  config.render.ambient = {kSky, kSky, kSky};
  config.render.shadows.method = ShadowMethod::Hard;
  config.render.shadows.ground_albedo = ground_albedo;
  SceneProxy wall;
  wall.name = "wall";
  wall.mesh = "builtin:box";
  wall.size_m = {0.02, 0.4, 0.3};
  wall.position_m = {0.07, 0.0, 0.0};
  wall.roles = ProxyRoles{true, true, false, false};  // hides and catches; casts nothing
  config.render.proxies = {wall};
  return config;
}

struct FaceReading {
  double umbra = 0, lit = 0;
  int umbra_pixels = 0, lit_pixels = 0;
};

// Over a white camera frame the output's linear value is the catcher's ratio. Pixels whose ray
// meets the wall's -x face first (the cube, nearer the camera, is missed), well inside the umbra
// or well outside the shadow.
FaceReading read_face(double ground_albedo) {
  harness().configure(wall_config(ground_albedo));
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 300.0, 159.5, 119.5, kWidth, kHeight));
  const SE3 pose = look_at({-0.15, -0.25, 0.15}, {0.06, 0.0, 0.025});
  Frame white = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  FrameContext ctx = make_context(white, camera, pose);
  harness().process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  const SE3 T_world_cam = pose.inverse();
  FaceReading reading;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const std::optional<Vec3> ray = camera->unproject({double(x), double(y)});
      if (!ray || ray_hits_box(pose, kCube, *ray) || ray_hits_box(pose, kWall, *ray) != std::optional<int>(0)) continue;
      const Vec3 origin = T_world_cam.translation(), d = T_world_cam.rotate(*ray);
      const Vec3 p = origin + ((kWall.min[0] - origin[0]) / d[0]) * d;
      const double value = decode_srgb(ctx.output.data[size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3 + 1] / 255.0);
      if (std::abs(p[1]) < 0.022 && p[2] > 0.006 && p[2] < 0.035) {
        reading.umbra += value;
        ++reading.umbra_pixels;
      } else if (std::abs(p[1]) > 0.06 || p[2] > 0.08) {
        reading.lit += value;
        ++reading.lit_pixels;
      }
    }
  if (reading.umbra_pixels) reading.umbra /= reading.umbra_pixels;
  if (reading.lit_pixels) reading.lit /= reading.lit_pixels;
  return reading;
}

TEST(ProxyCatcher, AVerticalFaceTakesTheSkyAboveTheHorizonAndTheGroundsBounce) {
  const double direct = kLight * -kTowardsLight[0];  // the face's normal is -x
  for (double albedo : {0.0, 0.5}) {
    const FaceReading face = read_face(albedo);
    const double ambient = kSky / 2 + albedo * (kLight * kTowardsLight[2] + kSky) / 2;
    const double expected = ambient / (ambient + direct);
    std::printf("ground albedo %.1f: umbra %.4f over %d px (expected %.4f), lit %.4f over %d px\n", albedo, face.umbra,
                face.umbra_pixels, expected, face.lit, face.lit_pixels);
    EXPECT_GT(face.umbra_pixels, 100);
    EXPECT_GT(face.lit_pixels, 1000);
    // 8-bit sRGB output: steps of about 0.003 at these values.
    EXPECT_NEAR(face.umbra, expected, 0.01) << "ground albedo " << albedo;
    EXPECT_NEAR(face.lit, 1.0, 0.002);
  }
  // The whole sphere's ambient (what the catcher took before) would give 0.25: far from both.
}

}  // namespace
}  // namespace arpipe
