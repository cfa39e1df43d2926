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
#include "gl_readback.h"
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

// Hand-made inputs that drive a bake: a GL context, the renderer, a ground catcher over the square
// of half-side `half` centred at the origin, and a shadow lookup of no texture (reads nothing, so
// every ground point is lit).
struct BakeInputs {
  explicit BakeInputs(double half) : catcher(receiver.over(ReceiverPatch{0, {-half, -half}, {half, half}})) {
    lookup.method = ShadowMethod::Hard;
    lighting.shadow = &lookup;
    lighting.color = {1, 1, 1};
    lighting.ambient = {0.3, 0.3, 0.3};
  }
  EglContext context{EglPlatformRequest::Auto};
  ObjectRenderer renderer;
  ShadowReceiver receiver{1};
  const UploadedObject& catcher;
  ShadowLookup lookup;
  Lighting lighting;
};

// The bake's policy.
TEST(CatcherBake, BakesOnceForAStillLightAndLeavesAChurningOneToThePerPixelPath) {
  BakeInputs inputs(0.1);
  ObjectRenderer& renderer = inputs.renderer;
  const UploadedObject& catcher = inputs.catcher;
  Lighting& lighting = inputs.lighting;
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
  // 16 cubes 7 cm apart seen from 0.45 m need 955-1127 texels across (bench/pipeline_scaling):
  // their catcher is baked, not drawn per pixel.
  EXPECT_GE(kMaxCatcherBakeTexels, 1127);
  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 1127, false).texture, 0u) << "16 cubes' square: baked";
  EXPECT_EQ(bake.bakes(), 6u);
  EXPECT_EQ(bake.for_frame(renderer, lighting, catcher, kMaxCatcherBakeTexels + 1, false).texture, 0u)
      << "too close for a bake: per pixel";
  EXPECT_EQ(CatcherBake(false).for_frame(renderer, lighting, catcher, 300, false).texture, 0u) << "no float target";
}

// A light infinitely far reaches the catcher's ratio through its cosine on the ground alone (the
// shadow maps are compared apart): turned around the vertical it needs no new bake, and a bake
// made afresh under the turned light holds the same texels within the key's 1/1000 (they are the
// same: the shader's cosine is the direction's z). A light that changes that cosine by 2 % is baked
// anew, and its bake differs by more than 1/1000; a lamp is still compared by its place.
TEST(CatcherBake, AFarLightCountsOnlyThroughItsCosineOnTheGround) {
  BakeInputs inputs(0.2);
  ObjectRenderer& renderer = inputs.renderer;
  const UploadedObject& catcher = inputs.catcher;
  Lighting& lighting = inputs.lighting;
  lighting.radiance_sh[0] = {0.3, 0.3, 0.3};
  lighting.sky_occluders = {{0.0f, 0.0f, 0.03f, 0.03f}};  // darkens the ground by the direct light's share
  lighting.catcher_patch = {-0.2f, -0.2f, 0.2f, 0.2f};
  constexpr int kSize = 256;  // 200 texels needed: the next power of two
  const auto texels = [&](const Lighting::BakedCatcher& baked) {
    std::vector<float> rgba = read_rgba_float(baked.texture, kSize, kSize);
    std::vector<float> red(size_t(kSize) * kSize);
    for (size_t i = 0; i < red.size(); ++i) red[i] = rgba[4 * i];
    return red;
  };
  const auto largest_difference = [](const std::vector<float>& a, const std::vector<float>& b) {
    double d = 0;
    for (size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(double(a[i]) - double(b[i])));
    return d;
  };

  lighting.direction = normalized(Vec3{0.3, -0.4, 1.0});
  CatcherBake bake(true);
  const Lighting::BakedCatcher first = bake.for_frame(renderer, lighting, catcher, 200, false);
  ASSERT_NE(first.texture, 0u);
  const std::vector<float> before = texels(first);
  ASSERT_GT(std::count_if(before.begin(), before.end(), [](float v) { return v > 0.01f; }), 100)
      << "the occluder darkens the ground";

  lighting.direction = normalized(Vec3{0.4, 0.3, 1.0});  // turned 90 degrees around the vertical
  ASSERT_NE(bake.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);
  EXPECT_EQ(bake.bakes(), 1u) << "the same cosine on the ground: the bake serves";
  CatcherBake fresh(true);
  const std::vector<float> turned = texels(fresh.for_frame(renderer, lighting, catcher, 200, false));
  EXPECT_LE(largest_difference(before, turned), kCatcherBakeLightChange);

  lighting.direction = normalized(Vec3{0.3, -0.4, 0.9});  // its cosine on the ground 2.3 % larger
  ASSERT_NE(bake.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);
  EXPECT_EQ(bake.bakes(), 2u) << "another cosine on the ground: baked anew";
  CatcherBake steeper(true);
  EXPECT_GT(largest_difference(before, texels(steeper.for_frame(renderer, lighting, catcher, 200, false))),
            kCatcherBakeLightChange);

  // A lamp: its place is compared.
  lighting.local = true;
  lighting.position = {0.1, 0.0, 0.5};
  lighting.direction = normalized(lighting.position);
  CatcherBake lamp(true);
  ASSERT_NE(lamp.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);
  ASSERT_NE(lamp.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);
  EXPECT_EQ(lamp.bakes(), 1u);
  lighting.position = {0.1, 0.001, 0.5};  // 1 mm aside
  ASSERT_NE(lamp.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);
  EXPECT_EQ(lamp.bakes(), 2u) << "a lamp that moved is baked anew";
}

// GL's bilinear lookup of a size x size red texture at texture coordinate (u, v), clamped to the
// edge: what the baked catcher's shader reads.
double bilinear(const std::vector<float>& red, int size, double u, double v) {
  const double x = u * size - 0.5, y = v * size - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const auto texel = [&](int i, int j) {
    i = std::clamp(i, 0, size - 1), j = std::clamp(j, 0, size - 1);
    return double(red[size_t(j) * size_t(size) + size_t(i)]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
         fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1));
}

// The reach holds every lookup that is not exactly 0: a blob of nonzero texels (one at the
// square's edge on one side), then every point of a fine grid over the square outside the reach
// reads 0, and the nonzero texels' centres are inside it.
TEST(CatcherBake, TheReachHoldsEveryLookupThatIsNotZero) {
  constexpr int kSize = 64;
  const std::array<float, 4> square{-0.3f, 0.1f, 0.5f, 0.9f};  // 0.8 m a side
  std::vector<float> red(kSize * kSize, 0.0f);
  for (int y = 20; y <= 30; ++y)
    for (int x = 0; x <= 12; ++x) red[size_t(y) * kSize + size_t(x)] = 1e-4f * float(1 + x + y);
  red[size_t(40) * kSize + 25] = 0.5f;  // a lone texel
  const std::array<float, 4> reach = CatcherBake::reach_of(red, kSize, square);
  const double texel = 0.8 / kSize;
  EXPECT_FLOAT_EQ(reach[0], square[0]) << "clamped to the square";
  EXPECT_NEAR(reach[2], square[0] + (25.5 + 2) * texel, 1e-6);
  EXPECT_NEAR(reach[1], square[1] + (20.5 - 2) * texel, 1e-6);
  EXPECT_NEAR(reach[3], square[1] + (40.5 + 2) * texel, 1e-6);
  int outside = 0;
  for (int j = 0; j <= 800; ++j)
    for (int i = 0; i <= 800; ++i) {
      const double u = i / 800.0, v = j / 800.0;
      const double wx = square[0] + u * 0.8, wy = square[1] + v * 0.8;
      if (wx >= reach[0] && wx <= reach[2] && wy >= reach[1] && wy <= reach[3]) continue;
      ++outside;
      ASSERT_EQ(bilinear(red, kSize, u, v), 0.0) << "at (" << wx << ", " << wy << ")";
    }
  EXPECT_GT(outside, 300000) << "most of the square is outside the reach";
  // Nothing nonzero: no reach.
  const std::array<float, 4> none = CatcherBake::reach_of(std::vector<float>(kSize * kSize, 0.0f), kSize, square);
  EXPECT_GT(none[0], none[2]);
  EXPECT_GT(none[1], none[3]);
}

// A real bake's reach, read back by the bake itself: one virtual object hiding part of the sky at
// the square's centre darkens the ground around it, by a share that falls with the cube of the
// distance. Under a sky 10^4 times fainter than the sun (the shadow's own ratio then moves by
// less than float's resolution beyond ~0.1 m), the darkening is exactly 0 well inside the square.
// Every texel of the texture that is not 0 has its centre inside the reach, and the reach is the
// bounds of those centres grown by 2 texels at most. A lit ground with nothing over it has no reach.
TEST(CatcherBake, ARealBakesReachHoldsItsNonzeroTexels) {
  BakeInputs inputs(0.2);
  ObjectRenderer& renderer = inputs.renderer;
  const UploadedObject& catcher = inputs.catcher;
  Lighting& lighting = inputs.lighting;
  lighting.direction = {0, 0, 1};
  lighting.ambient = {1e-4, 1e-4, 1e-4};
  lighting.radiance_sh[0] = {1e-4, 1e-4, 1e-4};
  lighting.sky_occluders = {{0.0f, 0.0f, 0.01f, 0.01f}};
  lighting.catcher_patch = {-0.2f, -0.2f, 0.2f, 0.2f};
  CatcherBake bake(true);
  constexpr int kSize = 256;  // 200 texels needed: the next power of two
  const Lighting::BakedCatcher baked = bake.for_frame(renderer, lighting, catcher, 200, false);
  ASSERT_NE(baked.texture, 0u);
  const auto& r = baked.reach;
  std::printf("reach x %.4f..%.4f, y %.4f..%.4f of the square -0.2..0.2\n", r[0], r[2], r[1], r[3]);

  // The texture as the catcher reads it.
  GlFramebuffer framebuffer = create_framebuffer_for(baked.texture);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
  std::vector<float> rgba(size_t(kSize) * kSize * 4);
  glReadPixels(0, 0, kSize, kSize, GL_RGBA, GL_FLOAT, rgba.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  const double texel = 0.4 / kSize;
  double lo[2] = {1, 1}, hi[2] = {-1, -1};
  size_t nonzero = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      if (rgba[(size_t(y) * kSize + size_t(x)) * 4] != 0.0f) {
        ++nonzero;
        const double c[2] = {-0.2 + (x + 0.5) * texel, -0.2 + (y + 0.5) * texel};
        for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
      }
  ASSERT_GT(nonzero, 100u) << "the occluder darkens the ground";
  for (int a = 0; a < 2; ++a) {
    EXPECT_GT(lo[a], -0.18) << "the darkening ends inside the square";
    EXPECT_LT(hi[a], 0.18) << "the darkening ends inside the square";
  }
  for (int a = 0; a < 2; ++a) {
    // (The square's edge clamps it: nothing reads beyond the square.)
    EXPECT_LE(r[size_t(a)], std::max(-0.2, lo[a] - 0.99 * texel) + 1e-6);
    EXPECT_GE(r[size_t(a)], std::max(-0.2, lo[a] - 2.01 * texel) - 1e-6);
    EXPECT_GE(r[size_t(a + 2)], std::min(0.2, hi[a] + 0.99 * texel) - 1e-6);
    EXPECT_LE(r[size_t(a + 2)], std::min(0.2, hi[a] + 2.01 * texel) + 1e-6);
  }

  EXPECT_NE(bake.for_frame(renderer, lighting, catcher, 200, false).texture, 0u);  // a still frame
  lighting.sky_occluders.clear();
  const Lighting::BakedCatcher lit = bake.for_frame(renderer, lighting, catcher, 200, false);
  ASSERT_NE(lit.texture, 0u);
  EXPECT_GT(lit.reach[0], lit.reach[2]) << "nothing drawn: no reach";
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
