// The panorama as the light (light.source = "panorama"): its SH against the analytic projections of
// uniform and half-and-half panoramas, placed as the panorama is (top = world +z, centre = world +y,
// turned by its yaw); a video's subsampled blocks against every texel; the source carrying it on
// each frame and the light stage passing it on with the config's direct light.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "capture/panorama/panorama_light.h"
#include "capture/panorama/panorama_source.h"
#include "core/environment/hdr_environment.h"
#include "core/image/srgb.h"
#include "core/light/light_stage.h"
#include "core/pipeline/frame_context.h"
#include "tests/capture/capture_test_support.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;
// y_1,-1 = c y, y_1,0 = c z, y_1,1 = c x (Green's order, core/sh/sh_basis.h).
const double kY1 = std::sqrt(3 / (4 * kPi));

double linear(int byte) { return srgb_decode(byte / 255.0); }

// A W x H panorama whose texel (x, y) has the grey byte value(x, y).
template <class F>
EquirectImage grey_panorama(int W, int H, F value) {
  std::vector<uint8_t> rgb(size_t(W) * size_t(H) * 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (size_t k = 0; k < 3; ++k) rgb[(size_t(y) * size_t(W) + size_t(x)) * 3 + k] = uint8_t(value(x, y));
  return EquirectImage(std::move(rgb), W, H, "test");
}

TEST(PanoramaLight, AUniformPanoramaIsAConstantRadiance) {
  // L00 = L sqrt(4 pi), the rest 0. The blocks' solid angles sum to 4 pi exactly (cosines
  // telescope) and the blocks' symmetry cancels every coefficient odd in a direction's component;
  // y_2,0 (3 z^2 - 1), even, integrates to 0 only within the centre-point quadrature's O(block^2)
  // error (blocks of 2 texels, pi / 128 tall: 1e-4 of L00).
  const PanoramaLight light(512, 256, default_world_from_probe(0));
  const ShRgb9 sh = light.project(grey_panorama(512, 256, [](int, int) { return 188; }));
  const double l00 = linear(188) * std::sqrt(4 * kPi);
  EXPECT_NEAR(sh[0][0], l00, 1e-12);
  for (size_t i = 1; i < 9; ++i) EXPECT_NEAR(sh[i][1], 0, i == 6 ? 1e-4 * l00 : 1e-12) << i;
}

TEST(PanoramaLight, HalvesLightFromWhereThePanoramaIsPlaced) {
  // Radiance a over one hemisphere and b over the other: L00 = (a + b) sqrt(pi) and, along the
  // hemisphere's axis, L1 = c pi (a - b); within the quadrature's O(block^2) error (2 texels a
  // block here: 1e-4 relative).
  constexpr int W = 512, H = 256;
  const double a = linear(230), b = linear(40);
  const double l1 = kY1 * kPi * (a - b);
  // The image's top half is the sky: world +z (index 2).
  const ShRgb9 up = PanoramaLight(W, H, default_world_from_probe(0)).project(grey_panorama(W, H, [](int, int y) {
    return y < H / 2 ? 230 : 40;
  }));
  EXPECT_NEAR(up[0][0], (a + b) * std::sqrt(kPi), 1e-12);
  EXPECT_NEAR(up[2][0], l1, 1e-4 * l1);
  EXPECT_NEAR(up[1][0], 0, 1e-12);
  EXPECT_NEAR(up[3][0], 0, 1e-12);
  // The image's middle half of columns (longitudes within 90 degrees of its centre) looks along
  // world +y (index 1); the panorama turned 90 degrees about z (counter-clockwise from above) sends
  // it along -x (index 3).
  const EquirectImage front = grey_panorama(W, H, [](int x, int) { return x >= W / 4 && x < 3 * W / 4 ? 230 : 40; });
  const ShRgb9 ahead = PanoramaLight(W, H, default_world_from_probe(0)).project(front);
  EXPECT_NEAR(ahead[1][0], l1, 1e-4 * l1);
  EXPECT_NEAR(ahead[3][0], 0, 1e-12);
  EXPECT_NEAR(ahead[2][0], 0, 1e-12);
  const ShRgb9 turned = PanoramaLight(W, H, default_world_from_probe(kPi / 2)).project(front);
  EXPECT_NEAR(turned[3][0], -l1, 1e-4 * l1);
  EXPECT_NEAR(turned[1][0], 0, 1e-12);
}

TEST(PanoramaLight, AVideosSubsampledBlocksAgreeWithEveryTexel) {
  // A 2048 x 1024 panorama (blocks of 8 texels) of a smooth field plus texel noise: a block's mean
  // from 4 x 4 of its 64 texels against all of them, within 0.5 % of L00 on every coefficient.
  constexpr int W = 2048, H = 1024;
  const EquirectImage image = grey_panorama(W, H, [](int x, int y) {
    const double u = 2 * kPi * x / W, v = kPi * y / H;
    return std::lround(120 + 80 * std::sin(v) * std::cos(u) + 40 * std::cos(v) + ((x * 7 + y * 13) % 5) - 2);
  });
  const PanoramaLight light(W, H, default_world_from_probe(0));
  ASSERT_EQ(light.block_side(), 8);
  const ShRgb9 all = light.project(image), some = light.project(image, 4);
  for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(some[i][0], all[i][0], 5e-3 * all[0][0]) << i;
}

TEST(PanoramaLight, AnHdrImagesRadianceIsUnclippedTimesItsScale) {
  HdrImage image{256, 128, std::vector<float>(256 * 128 * 3, 6.0f)};
  const ShRgb9 sh = PanoramaLight(256, 128, default_world_from_probe(0)).project(image, 0.5);
  EXPECT_NEAR(sh[0][2], 3.0 * std::sqrt(4 * kPi), 1e-12);
}

TEST(PanoramaLight, TheSourceCarriesItAndTheLightStagePassesItOn) {
  const auto dir = test::scratch_dir("panorama-light");
  const std::filesystem::path still = dir / "sky.png";
  cv::Mat bgr(256, 512, CV_8UC3, cv::Scalar(40, 40, 40));
  bgr(cv::Rect(0, 0, 512, 128)).setTo(cv::Scalar(230, 230, 230));  // the top half: the sky
  cv::imwrite(still.string(), bgr);
  Config config;
  config.source.type = SourceType::Panorama;
  config.source.pacing = ReplayPacing::Fast;
  config.source.panorama.file = still;
  config.source.panorama.view.width = 32;
  config.source.panorama.view.height = 24;
  config.source.panorama.view.frames = 2;
  config.light.source = LightSource::Panorama;
  config.render.light_direction = normalized(Vec3{0.2, 0.3, 0.9});
  config.render.light_color = {1.5, 1.5, 1.5};
  config.render.shadows.light_angular_diameter_deg = 1.0;

  PanoramaSource without(config.source);
  Frame frame;
  ASSERT_EQ(without.next(frame), SourceStatus::Frame);
  EXPECT_FALSE(frame.meta.environment_sh);  // computed only when asked

  PanoramaSource source(config.source, true);
  ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  ASSERT_TRUE(frame.meta.environment_sh);
  const double a = linear(230), b = linear(40);
  EXPECT_NEAR((*frame.meta.environment_sh)[0][1], (a + b) * std::sqrt(kPi), 1e-12);
  EXPECT_NEAR((*frame.meta.environment_sh)[2][1], kY1 * kPi * (a - b), 1e-4 * kY1 * kPi * (a - b));

  LightStage stage;
  stage.configure(config);
  FrameContext ctx;
  ctx.camera = frame;
  stage.process(ctx);
  EXPECT_EQ(ctx.light.state, LightState::Estimated);
  EXPECT_EQ(ctx.light.source, "panorama");
  EXPECT_TRUE(ctx.light.scene_linear);
  for (size_t i = 0; i < 9; ++i) EXPECT_EQ(ctx.light.ambient_sh[i], (*frame.meta.environment_sh)[i]) << i;
  // render.light_* as the shadow-casting light: irradiance = pi x light_color, as the fixed light's.
  ASSERT_EQ(ctx.light.lights.size(), 1u);
  EXPECT_EQ(ctx.light.lights[0].direction_world, config.render.light_direction);
  EXPECT_NEAR(ctx.light.lights[0].irradiance[0], kPi * 1.5, 1e-12);
  EXPECT_NEAR(ctx.light.lights[0].angular_diameter_rad, kPi / 180, 1e-15);

  // The panorama alone: no direct light. A frame without the light: none, said why.
  config.light.panorama.direct_light_from_render = false;
  stage.configure(config);
  stage.process(ctx);
  EXPECT_TRUE(ctx.light.lights.empty());
  ctx.camera.meta.environment_sh.reset();
  stage.process(ctx);
  EXPECT_EQ(ctx.light.state, LightState::None);
  EXPECT_FALSE(ctx.light.note.empty());
}

TEST(PanoramaLight, TheScenesExportedLightsAreTheDirectLightsStrongestFirst) {
  // light.panorama.lights_file: a sun shining straight down at 3 lux and a 20 cd lamp at (1, -3, 3)
  // (19 m^2 from the origin), times lights_scale 0.5: the sun (1.5, 1.35, 1.2) first, towards +z;
  // the lamp a local light there, 0.5 x 20 / 19 at the origin.
  const auto dir = test::scratch_dir("panorama-scene-lights");
  std::ofstream(dir / "lights.gltf") << R"({"asset": {"version": "2.0"},
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20.0},
                                                      {"type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 3.0}]}},
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"translation": [1.0, 3.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
              {"rotation": [-0.7071067811865476, 0.0, 0.0, 0.7071067811865476], "extensions": {"KHR_lights_punctual": {"light": 1}}}]})";
  Config config;
  config.source.type = SourceType::Panorama;
  config.light.source = LightSource::Panorama;
  config.light.panorama.lights_file = dir / "lights.gltf";
  config.light.panorama.lights_scale = 0.5;
  config.render.shadows.light_angular_diameter_deg = 0.5;
  LightStage stage;
  stage.configure(config);
  FrameContext ctx;
  ctx.camera.meta.environment_sh = ShRgb9{};
  stage.process(ctx);
  ASSERT_EQ(ctx.light.lights.size(), 2u);
  const DirectionalLight& sun = ctx.light.lights[0];
  EXPECT_FALSE(sun.local);
  EXPECT_NEAR(sun.direction_world[2], 1, 1e-12);
  EXPECT_NEAR(sun.irradiance[0], 1.5, 1e-12);
  EXPECT_NEAR(sun.irradiance[2], 1.2, 1e-12);
  EXPECT_NEAR(sun.angular_diameter_rad, 0.5 * kPi / 180, 1e-15);
  const DirectionalLight& lamp = ctx.light.lights[1];
  EXPECT_TRUE(lamp.local);
  EXPECT_NEAR(lamp.position_world[0], 1, 1e-12);
  EXPECT_NEAR(lamp.position_world[1], -3, 1e-12);
  EXPECT_NEAR(lamp.position_world[2], 3, 1e-12);
  EXPECT_NEAR(norm(lamp.direction_world), 1, 1e-12);
  EXPECT_NEAR(lamp.irradiance[1], 0.5 * 20 / 19, 1e-12);
  // A file without lights is a setup error naming the key.
  std::ofstream(dir / "none.gltf") << R"({"asset": {"version": "2.0"}, "nodes": [{}]})";
  config.light.panorama.lights_file = dir / "none.gltf";
  try {
    stage.configure(config);
    ADD_FAILURE() << "a lights file without lights was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("light.panorama.lights_file"), std::string::npos) << e.what();
  }
}

TEST(PanoramaLight, AnAnimatedLampStandsWhereTheVideoFramesTimePutsIt) {
  // A 20 cd lamp whose node moves linearly from glTF (1, 3, 3) at 0 s to (3, 3, -1) at 2 s (z-up:
  // from (1, -3, 3) to (3, 1, 3)): each frame's lamp is there at its source_frame_time_ns, held at
  // the last key after 2 s, and at the start on a frame without a time.
  const auto dir = test::scratch_dir("panorama-animated-lights");
  std::ofstream(dir / "lights.gltf") << R"({"asset": {"version": "2.0"},
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20.0}]}},
    "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "lamp", "translation": [1.0, 3.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
    "buffers": [{"byteLength": 32, "uri": "data:application/octet-stream;base64,AAAAAAAAAEAAAIA/AABAQAAAQEAAAEBAAABAQAAAgL8="}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 8}, {"buffer": 0, "byteOffset": 8, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0.0], "max": [2.0]},
                  {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "animations": [{"name": "walk", "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                    "samplers": [{"input": 0, "output": 1, "interpolation": "LINEAR"}]}]})";
  Config config;
  config.source.type = SourceType::Panorama;
  config.light.source = LightSource::Panorama;
  config.light.panorama.lights_file = dir / "lights.gltf";
  LightStage stage;
  stage.configure(config);
  const auto lamp_at = [&](std::optional<int64_t> t_ns) {
    FrameContext ctx;
    ctx.camera.meta.environment_sh = ShRgb9{};
    ctx.camera.meta.source_frame_time_ns = t_ns;
    stage.process(ctx);
    EXPECT_EQ(ctx.light.lights.size(), 1u);
    EXPECT_TRUE(ctx.light.note.empty()) << ctx.light.note;
    return ctx.light.lights.empty() ? Vec3{0, 0, 0} : ctx.light.lights[0].position_world;
  };
  for (const auto& [t_ns, expected] : {std::pair{std::optional<int64_t>(0), Vec3{1, -3, 3}},
                                       std::pair{std::optional<int64_t>(1'000'000'000), Vec3{2, -1, 3}},
                                       std::pair{std::optional<int64_t>(500'000'000), Vec3{1.5, -2, 3}},
                                       std::pair{std::optional<int64_t>(5'000'000'000), Vec3{3, 1, 3}},
                                       std::pair{std::optional<int64_t>(), Vec3{1, -3, 3}}}) {
    const Vec3 at = lamp_at(t_ns);
    for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(at[i], expected[i], 1e-6) << "at " << t_ns.value_or(-1) << " ns, axis " << i;
  }
  // An animation name the file does not have is a setup error naming the key.
  config.light.panorama.lights_animation = "run";
  try {
    stage.configure(config);
    ADD_FAILURE() << "an animation the file lacks was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("light.panorama.lights_file"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("run"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe
