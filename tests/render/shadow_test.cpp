// Virtual shadows on the real ground against the simulator's ray-traced truth
// (bench/shadow_comparison.h): the virtual balls of probe-indoor (a lamp) and sun-outdoor.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "bench/shadow_comparison.h"
#include "capture/sim/sim_scene_loader.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

const std::filesystem::path kScenes = std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs/sim";
using bench::ShadowComparison;
using bench::ShadowScene;

ShadowComparison compare(const ShadowScene& scene, const std::string& method) {
  return bench::compare_shadow(kScenes, scene, method);
}

// The bar: the best method within 0.05 mean absolute error of the ray-traced truth.
// What stays: the fill light's own faint shadow (about 5 % of the ground's light) and the sky the
// ball hides, neither of which one directional light plus ambient models.
TEST(Shadows, PcssMatchesTheRayTracedSunShadow) {
  const ShadowComparison c = compare(bench::sun_outdoor_shadow_scene(), "pcss");
  std::printf("sun pcss: MAE %.4f over %d px (truth min %.3f)\n", c.mae, c.pixels, c.truth_min);
  EXPECT_GT(c.pixels, 200);
  EXPECT_LE(c.mae, 0.05);
}

TEST(Shadows, PcssMatchesTheRayTracedShadowFactor) {
  const ShadowComparison c = compare(bench::probe_indoor_shadow_scene(), "pcss");
  RecordProperty("mae", std::to_string(c.mae));
  std::printf("pcss: MAE %.4f over %d px (truth min %.3f)\n", c.mae, c.pixels, c.truth_min);
  EXPECT_GT(c.pixels, 200);
  EXPECT_LT(c.truth_min, 0.3);  // the key's umbra is in the region
  EXPECT_LE(c.mae, 0.05);
}

// The sky the object hides from the ground beside it (render.shadows.sky_occlusion): outdoors,
// where the ambient light is the sky, it brings the shadow closer to the truth (measured: 0.0327
// without, 0.0112 with); indoors the fill light comes from one side, which the comparison's
// uniform ambient does not model, and it changes the error by under 0.005 either way.
TEST(Shadows, SkyOcclusionBringsTheOutdoorShadowCloserToTheTruth) {
  const ShadowComparison without = compare(bench::sun_outdoor_shadow_scene(), "pcss");
  const ShadowComparison with = compare(bench::sun_outdoor_shadow_scene(), "pcss+sky");
  std::printf("sun pcss: MAE %.4f without sky occlusion, %.4f with\n", without.mae, with.mae);
  EXPECT_LT(with.mae, 0.6 * without.mae);
  EXPECT_LE(with.mae, 0.02);
  const ShadowComparison lamp_without = compare(bench::probe_indoor_shadow_scene(), "pcss");
  const ShadowComparison lamp_with = compare(bench::probe_indoor_shadow_scene(), "pcss+sky");
  std::printf("lamp pcss: MAE %.4f without sky occlusion, %.4f with\n", lamp_without.mae, lamp_with.mae);
  EXPECT_LE(lamp_with.mae, 0.05);
  EXPECT_LT(std::abs(lamp_with.mae - lamp_without.mae), 0.005);
}

// The filtered-hard methods lack the penumbra's physical width but must put the shadow in the
// right place and depth: a misplaced shadow scores about 0.5, one of the wrong depth 0.2 or more.
// (Measured: 0.047 to 0.049; the seed's 256-based packing, before the k/255 fix, scored 0.22.)
TEST(Shadows, EveryMethodPutsTheShadowInThePlaceOfTheTruth) {
  for (const std::string method : {"hard", "pcf", "vsm", "vsm-packed"}) {
    const ShadowComparison c = compare(bench::probe_indoor_shadow_scene(), method);
    std::printf("%s: MAE %.4f over %d px\n", method.c_str(), c.mae, c.pixels);
    EXPECT_LE(c.mae, 0.08) << method;
  }
}

// The map is drawn once while light and objects stay put, and not at all without direct light
// or with the light below the ground.
TEST(Shadows, MapIsReusedAndSkippedWhenItCannotMatter) {
  const ShadowScene setup = bench::sun_outdoor_shadow_scene();
  const sim::SimScene scene = sim::load_sim_scene(kScenes / setup.file);
  auto camera = std::make_shared<const CameraModel>(scene.camera.model);
  Frame white = Frame::allocate(PixelFormat::RGB24, camera->width(), camera->height());
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  StageHarness stages;
  Config config = bench::shadow_config(setup, "pcf");
  stages.configure(config);
  std::vector<std::string> skips;
  for (int i = 0; i < 3; ++i) {
    FrameContext ctx = make_context(white, camera, setup.camera);
    stages.process(ctx);
    const StageTiming* shadow = find_timing(ctx, "shadow");
    ASSERT_NE(shadow, nullptr);
    skips.push_back(shadow->skipped);
  }
  EXPECT_EQ(skips, (std::vector<std::string>{"", "reused", "reused"}));

  config.render.light_direction = normalized(Vec3{1, 0, -0.2});  // under the ground plane
  stages.configure(config);
  FrameContext below = make_context(white, camera, setup.camera);
  stages.process(below);
  ASSERT_NE(find_timing(below, "shadow"), nullptr);
  EXPECT_EQ(find_timing(below, "shadow")->skipped, "light below the ground");

  config.render.light_direction = setup.towards_light;
  config.render.light_color = {0, 0, 0};
  stages.configure(config);
  FrameContext dark = make_context(white, camera, setup.camera);
  stages.process(dark);
  EXPECT_EQ(find_timing(dark, "shadow")->skipped, "no direct light");
}

}  // namespace
}  // namespace arpipe
