// Virtual shadows on the real ground against the simulator's ray-traced truth: probe-indoor's
// virtual ball under its key light, drawn by the render and composite stages over a white camera
// frame (so each output pixel decodes to the shadow ratio the catcher applied), against the
// ratio of the simulator's radiance with and without the ball (capture/sim/shadow_factor.h).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "capture/sim/shadow_factor.h"
#include "capture/sim/sim_scene_loader.h"
#include "core/image/srgb.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

const std::filesystem::path kScenes = std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs/sim";

// What a scene's header comment says about its virtual ball, its light and the camera's first
// keyframe; the light as a config's fixed light: the direct light as seen from the ball, the rest
// (fill light, sky) as ambient. Only their ratio matters to the catcher.
struct ShadowScene {
  std::string file;
  Vec3 ball_centre;
  double ball_radius;
  Vec3 towards_light;   // from the ball
  Vec3 light_position;  // a lamp; zero: infinitely far
  Vec3 direct;   // irradiance on a surface facing the light
  Vec3 ambient;  // irradiance on the ground from everything else
  double light_diameter_rad;
  SE3 camera;
  std::array<double, 4> ground_xy;  // x0, x1, y0, y1: the ground around the ball and its shadow
};

ShadowScene probe_indoor() {
  // Key: sphere light r 0.03 m at [-0.45, 0.05, 0.45], 2.5 W/sr, colour [1, 0.95, 0.85]; fill:
  // point light at [0.5, -0.4, 0.6], 0.4 W/sr, [0.85, 0.9, 1.0]; sky 0.04 W/(m^2 sr).
  const Vec3 ball{-0.13, -0.09, 0.0295};
  const Vec3 to_key = Vec3{-0.45, 0.05, 0.45} - ball;
  const double d = norm(to_key);
  const Vec3 to_fill = Vec3{0.5, -0.4, 0.6} - Vec3{ball[0], ball[1], 0};
  const double fill = 0.4 / dot(to_fill, to_fill) * normalized(to_fill)[2];
  return {"probe-indoor.toml", ball, 0.03, normalized(to_key), {-0.45, 0.05, 0.45}, (2.5 / (d * d)) * Vec3{1.0, 0.95, 0.85},
          fill * Vec3{0.85, 0.9, 1.0} + (std::numbers::pi * 0.04) * Vec3{1, 1, 1}, 2 * std::asin(0.03 / d),
          look_at({0.04, -0.42, 0.40}, {0.0, 0.04, 0.02}), {-0.22, 0.05, -0.22, 0.0}};
}

ShadowScene sun_outdoor() {
  // Sun at azimuth 135, elevation 40 (0.53 degree disc), 1000 W/m^2 x [1, 0.96, 0.90]; sky
  // [18, 24, 38] W/(m^2 sr).
  const Vec3 sun{0.5417, -0.5417, 0.6428};
  return {"sun-outdoor.toml", {0.15, -0.10, 0.0395}, 0.04, normalized(sun), {0, 0, 0}, 1000.0 * Vec3{1.0, 0.96, 0.90},
          std::numbers::pi * Vec3{18, 24, 38}, 0.53 * std::numbers::pi / 180,
          look_at({0.08, -0.50, 0.45}, {0.02, 0.05, 0.0}), {0.0, 0.25, -0.25, 0.05}};
}

// The truth's light as the fixed light of a config: the key light as seen from the ball, the
// fill and the sky as ambient. Only their ratio matters to the catcher.
Config shadow_config(const ShadowScene& scene, const std::string& method, int map_size = 1024) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:sphere";  // r 0.03 m, resting on z = 0
  config.render.objects[0].position_m = {scene.ball_centre[0], scene.ball_centre[1], scene.ball_centre[2] - scene.ball_radius};
  config.render.objects[0].scale = scene.ball_radius / 0.03;
  config.render.objects[0].color = {0.5, 0.5, 0.5};
  config.render.light_direction = scene.towards_light;
  if (norm(scene.light_position) > 0) {
    config.render.light_direction = normalized(scene.light_position);
    config.render.light_distance_m = norm(scene.light_position);
  }
  config.render.light_color = (1 / std::numbers::pi) * scene.direct;
  config.render.ambient = (1 / std::numbers::pi) * scene.ambient;
  config.render.shadows.method = method;
  config.render.shadows.map_size = map_size;
  config.render.shadows.receiver_height_m = -0.0005;
  config.render.shadows.light_angular_diameter_deg = scene.light_diameter_rad * 180 / std::numbers::pi;
  config.render.blur.method = "off";
  return config;
}

struct Truth {
  sim::ShadowFactorImage image;
  sim::PixelRegion region;
};

// The ground around the ball and its shadow, ray traced once per scene (64 light samples: the
// penumbra's noise is about 0.06 at worst per pixel, far less on average).
const Truth& truth(const ShadowScene& setup) {
  static std::map<std::string, Truth> cache;
  auto found = cache.find(setup.file);
  if (found != cache.end()) return found->second;
  {
    const sim::SimScene scene = sim::load_sim_scene(kScenes / setup.file);
    const CameraModel& camera = scene.camera.model;
    const SE3 T_cam_world = setup.camera;
    int x0 = camera.width(), y0 = camera.height(), x1 = 0, y1 = 0;
    for (double x : {setup.ground_xy[0], setup.ground_xy[1]})
      for (double y : {setup.ground_xy[2], setup.ground_xy[3]})
        if (auto q = camera.project(T_cam_world * Vec3{x, y, 0})) {
          x0 = std::min(x0, int(std::floor((*q)[0])));
          x1 = std::max(x1, int(std::ceil((*q)[0])));
          y0 = std::min(y0, int(std::floor((*q)[1])));
          y1 = std::max(y1, int(std::ceil((*q)[1])));
        }
    Truth t;
    t.region = {x0, y0, x1, y1};
    t.image = sim::render_shadow_factor(scene, camera, T_cam_world, 64, t.region);
    return cache.emplace(setup.file, std::move(t)).first->second;
  }
}

struct Comparison {
  double mae = 0;       // over the shadow: pixels where either side is darkened by more than 2 %
  int pixels = 0;
  double truth_min = 1;
};

Comparison compare(const ShadowScene& setup, const std::string& method, int map_size = 1024) {
  const sim::SimScene scene = sim::load_sim_scene(kScenes / setup.file);
  auto camera = std::make_shared<const CameraModel>(scene.camera.model);
  StageHarness stages;
  stages.configure(shadow_config(setup, method, map_size));
  Frame white = Frame::allocate(PixelFormat::RGB24, camera->width(), camera->height());
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  FrameContext ctx = make_context(white, camera, setup.camera);
  stages.process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  const Truth& t = truth(setup);
  Comparison c;
  double sum = 0;
  for (int y = t.region.y0; y < t.region.y1; ++y)
    for (int x = t.region.x0; x < t.region.x1; ++x) {
      if (!t.image.valid_at(x, y)) continue;
      // The ball's outline: the truth samples pixel centres, the layer covers pixel areas.
      bool near_ball = false;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx)
          near_ball |= x + dx >= t.region.x0 && x + dx < t.region.x1 && y + dy >= t.region.y0 && y + dy < t.region.y1 &&
                       !t.image.valid_at(x + dx, y + dy);
      if (near_ball) continue;
      const double ours = srgb_decode(ctx.output.data[size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3 + 1] / 255.0);
      const double truth_ratio = t.image.at(x, y);
      if (ours > 0.98 && truth_ratio > 0.98) continue;
      sum += std::abs(ours - truth_ratio);
      ++c.pixels;
      c.truth_min = std::min(c.truth_min, truth_ratio);
    }
  c.mae = c.pixels ? sum / c.pixels : 1.0;
  return c;
}

// The bar: the best method within 0.05 mean absolute error of the ray-traced truth.
// What stays: the fill light's own faint shadow (about 5 % of the ground's light) and the sky the
// ball hides, neither of which one directional light plus ambient models.
TEST(Shadows, PcssMatchesTheRayTracedSunShadow) {
  const Comparison c = compare(sun_outdoor(), "pcss");
  std::printf("sun pcss: MAE %.4f over %d px (truth min %.3f)\n", c.mae, c.pixels, c.truth_min);
  EXPECT_GT(c.pixels, 200);
  EXPECT_LE(c.mae, 0.05);
}

TEST(Shadows, PcssMatchesTheRayTracedShadowFactor) {
  const Comparison c = compare(probe_indoor(), "pcss");
  RecordProperty("mae", std::to_string(c.mae));
  std::printf("pcss: MAE %.4f over %d px (truth min %.3f)\n", c.mae, c.pixels, c.truth_min);
  EXPECT_GT(c.pixels, 200);
  EXPECT_LT(c.truth_min, 0.3);  // the key's umbra is in the region
  EXPECT_LE(c.mae, 0.05);
}

// The filtered-hard methods lack the penumbra's physical width but must put the shadow in the
// right place and depth: a misplaced shadow scores about 0.5, one of the wrong depth 0.2 or more.
// (Measured: 0.047 to 0.049; the seed's 256-based packing, before the k/255 fix, scored 0.22.)
TEST(Shadows, EveryMethodPutsTheShadowInThePlaceOfTheTruth) {
  for (const std::string method : {"hard", "pcf", "vsm", "vsm-packed"}) {
    const Comparison c = compare(probe_indoor(), method);
    std::printf("%s: MAE %.4f over %d px\n", method.c_str(), c.mae, c.pixels);
    EXPECT_LE(c.mae, 0.08) << method;
  }
}

// The map is drawn once while light and objects stay put, and not at all without direct light
// or with the light below the ground.
TEST(Shadows, MapIsReusedAndSkippedWhenItCannotMatter) {
  const ShadowScene setup = sun_outdoor();
  const sim::SimScene scene = sim::load_sim_scene(kScenes / setup.file);
  auto camera = std::make_shared<const CameraModel>(scene.camera.model);
  Frame white = Frame::allocate(PixelFormat::RGB24, camera->width(), camera->height());
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  StageHarness stages;
  Config config = shadow_config(setup, "pcf");
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
