// An object partly below the ground plane: what of it lies below stays hidden by the ground, as the
// real ground hides it (where the layer has ground: the catcher's patch). The ground catcher is drawn under the multisampled objects without depth
// (render/object_renderer.h, draw_ground_catcher_under), so its depth is laid down first on its own
// (draw_ground_catcher_depth); without it the sunk half would show through the ground.
#include <gtest/gtest.h>

#include <algorithm>

#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;

TEST(SunkObject, ThePartBelowTheGroundStaysHidden) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";  // 6 cm, its base at the object's origin
  config.render.objects[0].color = {0.8, 0.6, 0.4};
  // 1 cm of it below the ground: near enough to the cube that the ground there lies within the
  // catcher's patch (the shadows' reach, grown by twice the cube's sky radius), which is all the
  // ground the layer has.
  config.render.objects[0].position_m = {0.0, 0.0, -0.01};
  config.render.objects[0].prt = ObjectPrt::Off;
  // From beyond the cube, so that its shadow, and with it the catcher's patch, reaches towards the camera.
  config.render.light_direction = normalized(Vec3{0.4, 0.6, 0.7});
  ASSERT_EQ(config.render.shadows.method, ShadowMethod::Pcss);
  ASSERT_GT(config.render.msaa_samples, 1);
  StageHarness harness;
  harness.configure(config);
  const auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(300.0, 300.0, 159.5, 119.5, kWidth, kHeight));
  const SE3 pose = look_at({-0.20, -0.30, 0.12}, {0.0, 0.0, 0.0});
  Frame black = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(black.data.begin(), black.data.end(), uint8_t{0});
  FrameContext ctx = make_context(black, camera, pose);
  harness.process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);

  // Pixels whose ray meets the whole cube but not its part above z = -3 mm see the sunk part,
  // behind the ground: they keep the black camera picture. (The catcher lies at the receiver height,
  // 0.5 mm down, and a little further back in depth: a sliver just under the ground may show.)
  // Those that meet the part above the ground show the cube.
  const Box whole{{-0.03, -0.03, -0.01}, {0.03, 0.03, 0.05}}, above{{-0.03, -0.03, -0.003}, {0.03, 0.03, 0.05}};
  const std::vector<PixelTruth> whole_truth = classify_image(*camera, pose, whole, 1.0);
  const std::vector<PixelTruth> above_truth = classify_image(*camera, pose, above, 1.0);
  int below = 0, shown = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const size_t i = size_t(y) * kWidth + x;
      const uint8_t* out = ctx.output.data.data() + size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3;
      const int brightest = std::max({out[0], out[1], out[2]});
      if (whole_truth[i].cls == PixelClass::Inside && above_truth[i].cls == PixelClass::Outside) {
        ++below;
        ASSERT_LE(brightest, 2) << "the sunk part shows at (" << x << ", " << y << ")";
      }
      if (above_truth[i].cls == PixelClass::Inside && brightest > 40) ++shown;
    }
  EXPECT_GT(below, 100) << "the view must see where the sunk part lies";
  EXPECT_GT(shown, 500) << "the upper half shows";
}

}  // namespace
}  // namespace arpipe
