// The optional glossy reflection of the environment ([[render.objects]] specular): the 3-band
// radiance along the mirror direction, checked pixel by pixel on a flat face against the closed
// form for a sky whose radiance is linear in the direction's height.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;

StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

TEST(EnvironmentSpecular, ReflectsTheSkyAlongTheMirrorDirection) {
  // L(w) = a + b w_z: L00 = a sqrt(4 pi), L10 = b sqrt(4 pi / 3) (0.488603^2 4 pi / 3 = 1), both
  // band-limited already, so the reflection is exact: specular (a + b r_z), r the mirror direction.
  const double a = 0.3, b = 0.2, specular = 0.5;
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.objects[0].scale = 2.0;
  config.render.objects[0].color = {0, 0, 0};  // black: only the reflection shows
  config.render.objects[0].prt = ObjectPrt::Off;
  config.render.objects[0].specular = specular;
  config.render.msaa_samples = 0;
  config.render.shadows.method = ShadowMethod::Off;
  harness().configure(config);
  const Vec3 eye{0.22, -0.33, 0.30};
  const SE3 pose = look_at(eye, {0.01, 0.0, 0.05});
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(300, 300, 159.5, 119.5, kWidth, kHeight));
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  FrameContext ctx = make_context(black, camera, pose);
  ctx.camera.meta.exposure_ns = 1'000'000'000;  // exposure 1 s, gain 1: pixel = radiance
  ctx.light.state = LightState::Estimated;
  ctx.light.scene_linear = true;
  ctx.light.ambient_sh[0] = {a * std::sqrt(4 * std::numbers::pi), a * std::sqrt(4 * std::numbers::pi),
                             a * std::sqrt(4 * std::numbers::pi)};
  const double l10 = b * std::sqrt(4 * std::numbers::pi / 3);
  ctx.light.ambient_sh[2] = {l10, l10, l10};
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);
  // Pixels whose ray meets the top face (z = 0.12) at least 5 mm inside its edges.
  const SE3 T_world_cam = pose.inverse();
  int checked = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3 dir = mat_mul(T_world_cam.rotation(), *camera->unproject({double(x), double(y)}));
      if (dir[2] >= 0) continue;
      const double t = (0.12 - eye[2]) / dir[2];
      const Vec3 p = eye + t * dir;
      if (std::abs(p[0]) > 0.055 || std::abs(p[1]) > 0.055) continue;
      const Vec3 view = normalized(p - eye);
      const double r_z = -view[2];  // reflect about +z
      const double expected = specular * (a + b * r_z);
      const uint8_t* out = ctx.output.data.data() + size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3;
      // 1 LSB: 8-bit rounding after a half-float layer.
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(out[c], encode_srgb_8bit(expected), 1) << "pixel " << x << ", " << y;
      ++checked;
    }
  EXPECT_GT(checked, 500);
}

}  // namespace
}  // namespace arpipe
