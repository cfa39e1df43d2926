// Seed 003's hybrid with a moving real object, against the simulator: configs/sim/proxies.toml's
// world plus a real post that crosses between the camera and the virtual cube, rendered as a 360°
// video (its frames at k / 30 s) and exported as a glTF whose node "post" carries the post's
// keyframes. Seen through the panorama source with the post as an animated proxy, the cube's
// occlusion edges follow the ray-traced coverage at 1080p (issue 23's bar: 1 px) on frames before,
// while and after the post hides it; the same proxy left at its first key does not.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "bench/proxy_comparison.h"
#include "capture/panorama/panorama_source.h"
#include "capture/sim/ground_truth_coverage.h"
#include "capture/sim/recording_files.h"
#include "capture/sim/scene_export.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/config/config.h"
#include "core/track/tag_tracker.h"
#include "render/gl_stages.h"
#include "tests/render/proxies_world_text.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;
const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs/proxies.toml";

constexpr int kPanoramaWidth = 1024, kPanoramaHeight = 512;
constexpr double kFps = 30;
constexpr int kViewWidth = 1920, kViewHeight = 1080;
constexpr double kViewHfovDeg = 60;
const Vec3 kViewpoint{-0.02, -0.33, 0.36};  // the proxies capture's first camera position
constexpr double kYawDeg = 14.04, kPitchDeg = -38.66;  // at the virtual cube
// The post's crossing: x from -0.10 m to 0.30 m over 1.2 s at y = -0.02 m, turning 90 degrees.
// The line of sight to the cube crosses y = -0.02 m near x = 0.10 m (frame 18).
constexpr std::array<int, 3> kFrames{16, 19, 27};
constexpr int kVideoFrames = 28;

fs::path work_dir() {
  static const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / fmt::format("panorama_animated_{}", getpid());
  return dir;
}

// configs/sim/proxies.toml's objects, lights and sky (with or without the virtual cube), and the post.
std::string world(bool with_virtual_cube) {
  const std::string objects = test::proxies_world(with_virtual_cube);
  const std::string post = R"(
[[object]]
name = "post"
shape = "mesh"
mesh = "builtin:box"
size_m = [0.06, 0.03, 0.18]
position = [-0.10, -0.02, 0.0]
albedo = [0.20, 0.55, 0.25]
[[object.keyframe]]
time_s = 0.0
position = [-0.10, -0.02, 0.0]
rotation_deg = [0.0, 0.0, 0.0]
[[object.keyframe]]
time_s = 0.6
position = [0.10, -0.02, 0.0]
rotation_deg = [0.0, 0.0, 45.0]
[[object.keyframe]]
time_s = 1.2
position = [0.30, -0.02, 0.0]
rotation_deg = [0.0, 0.0, 90.0]
)";
  const size_t lights = objects.find("[[light]]");
  return objects.substr(0, lights) + post + "\n" + objects.substr(lights);
}

std::string common_sections(int samples, int frames) { return test::proxies_world_sections(samples, frames); }

Vec3 view_forward() {
  return {std::cos(kPitchDeg * kDeg) * std::sin(kYawDeg * kDeg), std::cos(kPitchDeg * kDeg) * std::cos(kYawDeg * kDeg),
          std::sin(kPitchDeg * kDeg)};
}

std::string keyframe(const Vec3& position, const Vec3& forward) {
  const Vec3 at = position + forward;
  return fmt::format("[[trajectory.keyframe]]\ntime_s = 0\nposition = [{:.17g}, {:.17g}, {:.17g}]\n"
                     "look_at = [{:.17g}, {:.17g}, {:.17g}]\n",
                     position[0], position[1], position[2], at[0], at[1], at[2]);
}

fs::path simulate(const std::string& name, const sim::SimScene& scene) {
  const fs::path out = work_dir() / name;
  fs::remove_all(out);
  sim::SimulateOptions options;
  options.out_dir = out;
  sim::simulate(scene, options);
  return out;
}

struct Captures {
  fs::path video, scene_glb;
  sim::SimObject post;  // as the simulator moves it
  std::vector<fs::path> views;  // per kFrames entry: the view at that frame's time, with the cube's coverage
};

const Captures& captures() {
  static const Captures made = [] {
    Captures c;
    const std::string panorama_text =
        fmt::format("[camera]\nlensmodel = \"LENSMODEL_LONLAT\"\nintrinsics = [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n"
                    "width = {}\nheight = {}\npixel_format = \"RGB24\"\nexposure_ms = 1.0\nfps = {}\n",
                    kPanoramaWidth / (2 * kPi), kPanoramaHeight / kPi, (kPanoramaWidth - 1) / 2.0,
                    (kPanoramaHeight - 1) / 2.0, kPanoramaWidth, kPanoramaHeight, kFps) +
        common_sections(1, kVideoFrames) + keyframe(kViewpoint, {0, 1, 0}) + world(false);
    const sim::SimScene panorama = sim::parse_sim_scene(panorama_text, "panorama.toml", ARPIPE_SOURCE_DIR);
    for (const sim::SimObject& object : panorama.objects)
      if (object.name == "post") c.post = object;
    const fs::path frames = simulate("panorama", panorama);
    c.video = work_dir() / "panorama.mp4";
    sim::write_recording_as_video(frames, c.video, panorama.camera);
    c.scene_glb = work_dir() / "scene.glb";
    const std::vector<uint8_t> glb = sim::export_scene_glb(panorama);
    std::ofstream(c.scene_glb, std::ios::binary).write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));

    const double fx = 0.5 * kViewWidth / std::tan(0.5 * kViewHfovDeg * kDeg);
    const std::string view_text =
        fmt::format("[camera]\nlensmodel = \"LENSMODEL_PINHOLE\"\nintrinsics = [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n"
                    "width = {}\nheight = {}\npixel_format = \"RGB24\"\nexposure_ms = 1.0\nfps = {}\n",
                    fx, fx, (kViewWidth - 1) / 2.0, (kViewHeight - 1) / 2.0, kViewWidth, kViewHeight, kFps) +
        common_sections(4, 1) + keyframe(kViewpoint, view_forward()) + world(true);
    const sim::SimScene view = sim::parse_sim_scene(view_text, "view.toml", ARPIPE_SOURCE_DIR);
    for (int k : kFrames) c.views.push_back(simulate(fmt::format("view{}", k), sim::scene_at_time(view, k / kFps)));
    return c;
  }();
  return made;
}

// configs/proxies.toml's cube and real box and cylinder, the post from the exported glTF.
Config hybrid_config(bool animated) {
  Config config = load_config(kConfig);
  config.source.type = SourceType::Panorama;
  config.source.pacing = ReplayPacing::Fast;
  config.source.panorama.file = captures().video;
  config.source.panorama.position_m = kViewpoint;
  config.source.panorama.view.width = kViewWidth;
  config.source.panorama.view.height = kViewHeight;
  config.source.panorama.view.hfov_rad = kViewHfovDeg * kDeg;
  config.source.panorama.view.yaw_rad = kYawDeg * kDeg;
  config.source.panorama.view.pitch_rad = kPitchDeg * kDeg;
  config.source.panorama.view.fps = kFps;
  config.source.panorama.view.frames = kFrames.back() + 1;
  config.render.shadows.method = ShadowMethod::Off;  // the layer's alpha is then the cube's coverage alone
  config.render.blur.method = BlurMethod::Off;
  SceneProxy post;
  post.name = "post";
  post.mesh = captures().scene_glb.string();
  post.node = "post";
  post.roles.collide = false;
  if (animated) config.render.proxies.push_back(post);
  else {  // the post's box where the file puts it at rest (its first key), not following the video
    post.mesh = "builtin:box";
    post.node.clear();
    post.size_m = {0.06, 0.03, 0.18};
    post.position_m = {-0.10, -0.02, 0.0};
    config.render.proxies.push_back(post);
  }
  return config;
}

// The cube's occlusion edge error on each of kFrames, through the source and the real stages.
std::vector<bench::EdgeError> run_hybrid(bool animated, std::vector<double>* post_x = nullptr) {
  const Config config = hybrid_config(animated);
  PanoramaSource source(config.source);
  TagTracker tracker;
  tracker.configure(config);
  std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  for (auto& stage : stages) stage->configure(config);
  std::vector<bench::EdgeError> out;
  size_t next = 0;
  for (int k = 0; k <= kFrames.back(); ++k) {
    FrameContext ctx;
    EXPECT_EQ(source.next(ctx.camera), SourceStatus::Frame);
    if (k != kFrames[next]) continue;  // the source steps through the video; only these are drawn
    ctx.camera_model = source.camera_model();
    tracker.process(ctx);
    EXPECT_EQ(ctx.pose.state, TrackState::Tracking);
    for (auto& stage : stages) stage->process(ctx);
    EXPECT_EQ(ctx.camera.meta.source_frame_index, std::optional<int64_t>(k));
    if (animated && post_x) {
      EXPECT_TRUE(ctx.animation);
      if (ctx.animation && !ctx.animation->proxies.empty()) post_x->push_back(ctx.animation->proxies[0].position_m[0]);
    }
    EXPECT_TRUE(ctx.virtual_layer_drawn) << "frame " << k;
    if (!ctx.virtual_layer_drawn) return out;
    out.push_back(bench::occlusion_edge_error(bench::layer_alpha(ctx.virtual_layer),
                                              sim::read_coverage_frame(captures().views[next], 0)));
    ++next;
  }
  return out;
}

TEST(PanoramaAnimatedHybrid, AMovingProxyKeepsTheOcclusionEdgesOnTheRayTracedCoverageAt1080pAndAStillOneDoesNot) {
  std::vector<double> post_x;
  const std::vector<bench::EdgeError> edges = run_hybrid(true, &post_x);
  ASSERT_EQ(edges.size(), kFrames.size());
  ASSERT_EQ(post_x.size(), kFrames.size());
  ASSERT_FALSE(captures().post.keyframes.empty());
  for (size_t i = 0; i < kFrames.size(); ++i) {
    std::printf("frame %d: post at x = %.4f m, occlusion edge %.1f px long, mean displacement %.3f px\n", kFrames[i],
                post_x[i], edges[i].edge_length_px, edges[i].displacement_px);
    // The proxy stands where the simulator put the post for that frame.
    EXPECT_NEAR(post_x[i], sim::object_pose_at(captures().post, kFrames[i] / kFps).translation()[0], 1e-5) << "frame " << kFrames[i];
    EXPECT_GT(edges[i].edge_length_px, 400) << "frame " << kFrames[i];
    EXPECT_LE(edges[i].displacement_px, 1.0) << "frame " << kFrames[i];  // issue 23's bar
  }
  // The same proxy left at the post's first key (not following the video): the frames where the
  // post hides part of the cube are off by far more than the bar (the check has teeth). One test
  // with the one above: each test process simulates the captures again.
  const std::vector<bench::EdgeError> at_rest = run_hybrid(false);
  ASSERT_EQ(at_rest.size(), kFrames.size());
  double worst = 0;
  for (size_t i = 0; i < kFrames.size(); ++i) {
    std::printf("frame %d, proxy at rest: mean displacement %.3f px\n", kFrames[i], at_rest[i].displacement_px);
    worst = std::max(worst, at_rest[i].displacement_px);
  }
  EXPECT_GT(worst, 3.0);
}

}  // namespace
}  // namespace arpipe
