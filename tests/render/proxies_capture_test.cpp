// Phantom proxies against the simulator (configs/sim/proxies.toml, simulated by the build into
// build/proxies-capture): a real box and cylinder hide a virtual cube while the camera holds still
// and then swings. With the ground-truth camera motion (so that only the renderer is measured),
// the cube's drawn coverage is compared with the simulator's visible coverage of it, and its
// shadow on the box's face and on the floor with the ray-traced shadow ratio.
#include <GLES3/gl3.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>

#include "capture/recording/recording_reader.h"
#include "capture/sim/ground_truth_coverage.h"
#include "capture/sim/shadow_factor.h"
#include "capture/sim/sim_scene_loader.h"
#include "bench/proxy_comparison.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;
namespace fs = std::filesystem;

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "proxies-capture";
const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs/proxies.toml";
const fs::path kScene = fs::path(ARPIPE_SOURCE_DIR) / "configs/sim/proxies.toml";

StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

TEST(ProxiesCapture, OcclusionEdgesFollowTheSimulatorsCoverage) {
  ASSERT_TRUE(fs::exists(kCapture / "recording.json")) << kCapture << ": the build simulates it (proxies_capture)";
  Config config = load_config(kConfig);
  config.render.shadows.method = ShadowMethod::Off;  // the layer's alpha is then the cube's coverage alone
  const bench::ProxyCaptureRun run = bench::run_proxy_capture(kCapture, config);
  for (size_t i = 0; i < run.frames.size(); ++i) {
    const bench::ProxyFrame& f = run.frames[i];
    std::printf("frame %2zu: cube motion %5.2f px, blur %s x%d, edge %6.1f px, displacement %.3f px, hidden %.2f\n", i,
                f.motion_px, f.blur_method.c_str(), f.blur_samples, f.edge.edge_length_px, f.edge.displacement_px, f.hidden);
    EXPECT_GT(f.edge.edge_length_px, 100) << "frame " << i;
    // About half of the cube is behind the cylinder in every frame (the scene's own test).
    EXPECT_GT(f.hidden, 0.3) << "frame " << i;
  }
  std::printf("worst mean edge displacement: %.3f px over %d frames under 1 px of blur, %.3f px over %d blurred\n",
              run.worst_still_px, run.still_frames, run.worst_blurred_px, run.blurred_frames);
  EXPECT_GT(run.still_frames, 5);
  EXPECT_GT(run.blurred_frames, 3);
  EXPECT_LE(run.worst_still_px, 0.5);  // issue 22's bars
  EXPECT_LE(run.worst_blurred_px, 1.0);
}

// Where a camera ray (world) enters the proxy box of configs/proxies.toml: 12 x 8 x 10 cm, yawed
// 20 degrees, at (0.315, 0.16, 0), as its slab in the box's own frame.
std::optional<double> box_entry(const Vec3& origin, const Vec3& dir) {
  const SE3 T_world_box = SE3::from_rt({0, 0, 20 * std::numbers::pi / 180}, {0.315, 0.16, 0.0});
  const SE3 T_box_world = T_world_box.inverse();
  const Vec3 o = T_box_world * origin, d = T_box_world.rotate(dir);
  const Vec3 lo{-0.06, -0.04, 0.0}, hi{0.06, 0.04, 0.10};
  double t_near = -INFINITY, t_far = INFINITY;
  for (size_t a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return std::nullopt;
      continue;
    }
    double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0), t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_near <= 0) return std::nullopt;
  return t_near;
}

// The cube's shadow on the box's face and on the floor around it, against the simulator's ray
// traced ratio (radiance with the cube over radiance without, the same random light samples):
// issue 22's bar is the ground's, a mean absolute error of at most 0.05 over each surface's
// shadowed pixels (where either side darkens by more than 2 %). Frame 0: the camera holds still.
TEST(ProxiesCapture, TheCubesShadowOnTheBoxAndTheFloorMatchesTheRayTracedRatio) {
  ASSERT_TRUE(fs::exists(kCapture / "recording.json")) << kCapture << ": the build simulates it (proxies_capture)";
  RecordingReader reader(kCapture);
  const auto camera = std::make_shared<const CameraModel>(reader.camera_model());
  const GroundTruthFrame& truth_pose = reader.ground_truth()[0];
  const SE3 pose = truth_pose.T_cam_world_mid;
  const sim::SimScene scene = sim::load_sim_scene(kScene);
  const sim::ShadowFactorImage truth = sim::render_shadow_factor(scene, *camera, pose, 64, {0, 0, camera->width(), camera->height()});
  const sim::CoverageImage cube_coverage = sim::read_coverage_frame(kCapture, 0);

  const Config config = load_config(kConfig);
  harness().configure(config);
  Frame white = Frame::allocate(PixelFormat::RGB24, camera->width(), camera->height());
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  FrameContext ctx = make_context(white, camera, pose);
  harness().process(ctx);
  ASSERT_TRUE(ctx.virtual_layer_drawn);

  std::vector<Vec2> centres;
  for (int y = 0; y < camera->height(); ++y)
    for (int x = 0; x < camera->width(); ++x) centres.push_back({double(x), double(y)});
  std::vector<Vec3> rays;
  camera->unproject(centres, rays);
  const SE3 T_world_cam = pose.inverse();
  struct Surface {
    const char* name;
    double sum = 0;
    int pixels = 0;
    double truth_min = 1;
  };
  Surface box{"box face"}, floor{"floor"};
  for (int y = 0; y < camera->height(); ++y)
    for (int x = 0; x < camera->width(); ++x) {
      const size_t i = size_t(y) * camera->width() + x;
      if (!truth.valid_at(x, y) || cube_coverage.at(x, y) > 0) continue;  // the cube itself, or nothing
      const double drawn = decode_srgb(ctx.output.data[size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3 + 1] / 255.0);
      const double expected = truth.at(x, y);
      if (drawn > 0.98 && expected > 0.98) continue;
      const Vec3 dir = T_world_cam.rotate(rays[i]);
      const std::optional<double> on_box = box_entry(T_world_cam.translation(), dir);
      // The floor: a ray that meets the table plane z = -0.5 mm before anything else we know of.
      const bool on_floor = !on_box && dir[2] < 0;
      Surface* surface = on_box ? &box : on_floor ? &floor : nullptr;
      if (!surface) continue;
      surface->sum += std::abs(drawn - expected);
      ++surface->pixels;
      surface->truth_min = std::min(surface->truth_min, expected);
    }
  // Issue 22's bar, 0.05, on both (measured 0.047 on the face, 0.048 on the floor). The face
  // needs the catcher's ambient to be the sky above the ground's horizon ((1 + n_z) / 2 of its
  // view for the constant ambient; configs/proxies.toml's ground bounces nothing, as in the
  // simulator): with the whole sphere's ambient it was 0.071, and 0.135 without sky occlusion.
  for (const Surface* s : {&box, &floor}) {
    const double mae = s->pixels ? s->sum / s->pixels : 0.0;
    std::printf("%s: MAE %.4f over %d shadowed px (truth min %.3f)\n", s->name, mae, s->pixels, s->truth_min);
    EXPECT_GT(s->pixels, 150) << s->name;
    EXPECT_LT(s->truth_min, 0.5) << s->name << ": the umbra is there";
    EXPECT_LE(mae, 0.05) << s->name;
  }
}

}  // namespace
}  // namespace arpipe
