// Objects moved by the physics in the render stage: a dropped ball is drawn where the simulation
// has it at each frame's mid-exposure, its own fall blurs it though the camera is still, and a
// ball at rest lets the stage reuse the layer again.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "render/scene_physics.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;
constexpr int64_t kT0 = 1'000'000'000, kFrameNs = 33'333'333, kExposureNs = 20'000'000;

Config falling_ball_config() {
  Config config;
  SceneObject ball;
  ball.mesh = "builtin:sphere";
  ball.prt = ObjectPrt::Off;
  ball.color = {1, 1, 1};
  ball.position_m = {0, 0, 0.15};
  ball.physics.kind = ObjectMotion::Dynamic;
  ball.physics.restitution = 0.3;
  ball.physics.rolling_friction = 0.01;  // so that it settles
  config.render.objects = {ball};
  config.render.ambient = {1, 1, 1};
  config.render.light_color = {0, 0, 0};
  config.render.shadows.method = ShadowMethod::Off;
  config.render.blur.method = BlurMethod::Accumulate;
  return config;
}

// Side view, level with the fall.
SE3 side_pose() { return look_at({0.0, -0.6, 0.10}, {0.0, 0.0, 0.10}); }

FrameContext frame(int index, const Frame& black, const std::shared_ptr<const CameraModel>& camera) {
  FrameContext ctx = make_context(black, camera, side_pose());
  ctx.camera.meta.sequence = uint64_t(index);
  ctx.camera.meta.exposure_start_ns = kT0 + index * kFrameNs;
  ctx.camera.meta.exposure_ns = kExposureNs;
  ctx.camera.meta.frame_duration_ns = kFrameNs;
  return ctx;
}

// The ball's image centroid (linear coverage of the output over black).
Vec2 centroid(const Frame& out) {
  double sum = 0, sx = 0, sy = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double w = decode_srgb(out.data[size_t(y) * out.bytes_per_line + size_t(x) * 3] / 255.0);
      sum += w, sx += w * x, sy += w * y;
    }
  return {sx / sum, sy / sum};
}

TEST(PhysicsRender, TheBallIsDrawnWhereTheSimulationHasItAndItsFallBlurs) {
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(400, 400, 159.5, 119.5, kWidth, kHeight));
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  StageHarness stages;
  const Config config = falling_ball_config();
  stages.configure(config);
  // The same world, stepped alongside, says where the ball is.
  ScenePhysics truth(config, load_object_meshes(config));
  double worst_px = 0;
  bool blurred = false;
  for (int i = 0; i < 6; ++i) {  // 0.2 s: falling, not yet landed (it lands after 0.175 s... from 0.15 m)
    FrameContext ctx = frame(i, black, camera);
    stages.process(ctx);
    ASSERT_TRUE(ctx.virtual_layer_drawn) << "frame " << i;
    const int64_t start = ctx.camera.meta.exposure_start_ns;
    truth.advance(start, start + kExposureNs);
    // The centroid of the smear is the ball's centre's projection averaged over the exposure.
    Vec2 expected{0, 0};
    for (int k = 0; k < 64; ++k) {
      const SE3 T = truth.sample(0, start + (2 * k + 1) * kExposureNs / 128)->T_world_body;
      const Vec2 p = *camera->project(side_pose() * (T * Vec3{0, 0, 0.03}));
      expected = {expected[0] + p[0] / 64, expected[1] + p[1] / 64};
    }
    const Vec2 seen = centroid(ctx.output);
    const double error = std::hypot(seen[0] - expected[0], seen[1] - expected[1]);
    std::cout << "frame " << i << ": centroid (" << seen[0] << ", " << seen[1] << "), expected (" << expected[0]
              << ", " << expected[1] << "), " << error << " px, blur " << ctx.blur_method << " x" << ctx.blur_samples << "\n";
    worst_px = std::max(worst_px, error);
    blurred = blurred || ctx.blur_method == "accumulate";
  }
  // A 3 cm ball is 40 px across here: the centroid of its accumulated smear (and the 8-bit
  // encoding of its edge) within a fifth of a pixel of the mean projected centre.
  EXPECT_LE(worst_px, 0.2);
  EXPECT_TRUE(blurred);  // by 0.2 s it falls at 1.7 m/s: over 10 px per 20 ms exposure
}

TEST(PhysicsRender, ABallAtRestLetsTheLayerBeReused) {
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(400, 400, 159.5, 119.5, kWidth, kHeight));
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  StageHarness stages;
  Config config = falling_ball_config();
  config.render.objects[0].position_m = {0, 0, 0};  // on the ground already
  stages.configure(config);
  std::vector<std::string> skips;
  for (int i = 0; i < 4; ++i) {
    FrameContext ctx = frame(i, black, camera);
    stages.process(ctx);
    skips.push_back(find_timing(ctx, "render")->skipped);
  }
  EXPECT_EQ(skips[0], "");
  EXPECT_EQ(skips[3], "reused: pose, light and objects unchanged");
}

}  // namespace
}  // namespace arpipe
