// Tests of the ground catcher's bake (render/shadow/catcher_bake.h): when it bakes, reuses and
// leaves the catcher to be drawn per pixel; how many texels it asks for; and through the render
// stage, that the baked catcher draws the same picture as the per-pixel one.
#include "render/shadow/catcher_bake.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/gl/egl_context.h"
#include "render/shadow/shadow_receiver.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

TEST(CatcherBake, TexelsNeededAreTwicePerPixelAtTheNearestPoint) {
  UploadedObject catcher;
  catcher.scale = 0.2;  // a 20 cm square centred at (0.1, 0, 0)
  catcher.T_world_object = SE3::from_rt({0, 0, 0}, {0.1, 0.0, 0.0});
  // Half a metre straight above a point of the square: nearest at 0.5 m.
  const std::vector<SE3> above{look_at({0.05, 0.02, 0.5}, {0.05, 0.0, 0.0})};
  EXPECT_NEAR(catcher_texels_needed(catcher, above, 600.0), 2.0 * 0.2 * 600.0 / 0.5, 1e-9);
  // Beside it: 0.3 m from its edge across, 0.4 m up: 0.5 m.
  const std::vector<SE3> beside{look_at({0.5, 0.0, 0.4}, {0.1, 0.0, 0.0}), look_at({0.9, 0.0, 0.4}, {0.1, 0.0, 0.0})};
  EXPECT_NEAR(catcher_texels_needed(catcher, beside, 600.0), 2.0 * 0.2 * 600.0 / 0.5, 1e-9);
  const std::vector<SE3> on_it{SE3::from_rt({0, 0, 0}, {-0.1, 0.0, 0.0})};  // the eye at (0.1, 0, 0)
  EXPECT_TRUE(std::isinf(catcher_texels_needed(catcher, on_it, 600.0)));
}

// The bake's policy on hand-made inputs: a shadow lookup of no texture (reads nothing, so every
// ground point is lit) is enough to drive it.
TEST(CatcherBake, BakesOnceForAStillLightAndLeavesAChurningOneToThePerPixelPath) {
  EglContext context(EglPlatformRequest::Auto);
  ObjectRenderer renderer;
  ShadowReceiver receiver(1);
  ReceiverPatch patch;
  patch.min = {-0.1, -0.1};
  patch.max = {0.1, 0.1};
  const UploadedObject& catcher = receiver.over(patch);
  ShadowLookup lookup;
  lookup.method = ShadowMethod::Hard;
  Lighting lighting;
  lighting.shadow = &lookup;
  lighting.color = {1, 1, 1};
  lighting.ambient = {0.3, 0.3, 0.3};
  CatcherBake bake(true);

  Lighting::BakedCatcher baked = bake.for_frame(renderer, lighting, catcher, 300, false);
  EXPECT_NE(baked.texture, 0u) << "the first frame bakes";
  EXPECT_EQ(bake.bakes(), 1u);
  EXPECT_FLOAT_EQ(baked.square[0], -0.1f);
  EXPECT_FLOAT_EQ(baked.square[3], 0.1f);
  for (int frame = 0; frame < 5; ++frame) EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 300, false).texture, 0u);
  EXPECT_EQ(bake.bakes(), 1u) << "a still light is baked once";

  lighting.ambient = {0.31, 0.31, 0.31};  // changed after still frames: baked anew
  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 300, false).texture, 0u);
  EXPECT_EQ(bake.bakes(), 2u);
  lighting.ambient = {0.32, 0.32, 0.32};  // changed again the next frame: per pixel
  EXPECT_EQ(bake.for_frame(renderer, lighting, catcher, 300, false).texture, 0u);
  lighting.ambient = {0.33, 0.33, 0.33};
  EXPECT_EQ(bake.for_frame(renderer, lighting, catcher, 300, false).texture, 0u);
  EXPECT_EQ(bake.bakes(), 2u);
  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 300, false).texture, 0u) << "settled: baked again";
  EXPECT_EQ(bake.bakes(), 3u);

  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 300, true).texture, 0u) << "a redrawn map is new content";
  EXPECT_EQ(bake.bakes(), 4u);
  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 600, false).texture, 0u) << "closer: a larger bake";
  EXPECT_EQ(bake.bakes(), 5u);
  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 100, false).texture, 0u) << "farther: the larger one serves";
  EXPECT_EQ(bake.bakes(), 5u);
  EXPECT_EQ(bake.for_frame(renderer, lighting, catcher, kMaxCatcherBakeTexels + 1, false).texture, 0u)
      << "too close for a bake: per pixel";
  EXPECT_EQ(CatcherBake(false).for_frame(renderer, lighting, catcher, 300, false).texture, 0u) << "no float target";
}

// Through the render stage: a cube under a low light (a long shadow with a wide penumbra), seen
// from three places, with the catcher baked and drawn per pixel. The bake holds two texels per
// pixel and is read back filtered: it blurs the shadow's edges (the contact shadow at the cube's
// foot is the sharpest) by at most half a pixel, and smooths the per-pixel path's 1/36 steps of
// PCSS (2 levels at most). So no value may differ by more than half the step to a neighbour plus
// 2 levels, and under 0.2 % by more than one level.
TEST(CatcherBake, TheBakedCatcherDrawsThePerPixelPicture) {
  constexpr int kWidth = 320, kHeight = 240;
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.light_direction = normalized(Vec3{0.8, -0.3, 0.5});
  config.render.ambient = {0.25, 0.25, 0.25};
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 300.0, 159.5, 119.5, kWidth, kHeight));
  const SE3 poses[] = {look_at({-0.25, -0.3, 0.3}, {-0.05, 0.02, 0.0}), look_at({0.1, -0.45, 0.2}, {-0.05, 0.0, 0.0}),
                       look_at({-0.4, 0.1, 0.25}, {-0.05, 0.0, 0.0})};
  std::vector<Frame> outputs[2];
  for (int baked = 0; baked < 2; ++baked) {
    config.render.shadows.bake_catcher = baked == 1;
    StageHarness harness;
    harness.configure(config);
    for (const SE3& pose : poses) {
      FrameContext ctx = make_context(varied_background(kWidth, kHeight), camera, pose);
      harness.process(ctx);
      ASSERT_TRUE(ctx.virtual_layer_drawn);
      outputs[baked].push_back(ctx.output);
    }
  }
  const Frame background = varied_background(kWidth, kHeight);
  for (size_t f = 0; f < std::size(poses); ++f) {
    const Frame& a = outputs[0][f];
    const Frame& b = outputs[1][f];
    ASSERT_EQ(a.data.size(), b.data.size());
    const auto at = [&](const Frame& frame, int x, int y, int c) {
      return int(frame.data[size_t(y) * frame.bytes_per_line + size_t(x) * 3 + size_t(c)]);
    };
    size_t over_one = 0, beyond_blur = 0, darkened = 0;
    int worst = 0;
    for (int y = 1; y + 1 < kHeight; ++y)
      for (int x = 1; x + 1 < kWidth; ++x)
        for (int c = 0; c < 3; ++c) {
          const int d = std::abs(at(a, x, y, c) - at(b, x, y, c));
          // Half a pixel's blur moves a value by at most half the step to a neighbour.
          int step = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) step = std::max(step, std::abs(at(a, x + dx, y + dy, c) - at(a, x, y, c)));
          worst = std::max(worst, d);
          over_one += d > 1;
          beyond_blur += d > step / 2 + 2;
          darkened += at(a, x, y, c) + 8 < at(background, x, y, c);
        }
    std::printf("pose %zu: %zu channel values differ by more than 1, the most by %d, %zu by more than half the step "
                "to a neighbour and 2; %zu darkened by the shadow\n", f, over_one, worst, beyond_blur, darkened);
    EXPECT_GT(darkened, 3000u) << "pose " << f << ": the shadow shows";
    EXPECT_LT(over_one, a.data.size() / 500) << "pose " << f;
    EXPECT_EQ(beyond_blur, 0u) << "pose " << f;
  }
}

}  // namespace
}  // namespace arpipe
