// The acceptance test of lens-matched rendering (issue 5): small cubes spread over the whole image,
// corners included, seen through a strongly distorted lens by the simulator (ray cast through
// mrcal, independently of render/) and drawn as virtual objects by the render and composite
// stages from the recording's true pose: each cube's top face lands in the same place in both
// pictures, measured by intensity-weighted centroids, for render.lens = "map", "vertex" and
// "undistort" (the last compared in the undistorted picture).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <unistd.h>

#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 640, kHeight = 480;
// Strong barrel distortion: the corners' rays are 54 degrees off axis and the lens moves them
// about 150 px inwards from where the pinhole core would put them.
constexpr const char* kIntrinsics = "[400.0, 400.0, 322.3, 236.8, -0.30, 0.10, 0.001, -0.0008, -0.01, 0.0, 0.0, 0.0]";
constexpr double kCameraHeightM = 0.5;  // looking straight down at the world xy plane
constexpr double kCubeScale = 0.5;      // builtin:cube is 6 cm: 3 cm cubes, top faces ~25 px across
constexpr double kTopM = 0.06 * kCubeScale;
constexpr int kColumns = 7, kRows = 5;
constexpr int kBorderPx = 16;   // top-face centres this far from the image edges: corners included
constexpr int kWindowPx = 30;   // half-size of the window each blob is measured in (they are ~100 px apart)

CameraModel lens() {
  return CameraModel("LENSMODEL_OPENCV8", {400.0, 400.0, 322.3, 236.8, -0.30, 0.10, 0.001, -0.0008, -0.01, 0, 0, 0},
                     kWidth, kHeight);
}

// A captured scene: the simulated frame, its true pose, and where the cubes stand.
struct Capture {
  Frame frame;
  SE3 T_cam_world;
  std::vector<Vec3> cube_positions;  // world, base centres
  double simulate_seconds = 0;
};

// Cubes whose top-face centres fall on a kColumns x kRows grid of `placement` (the lens image, or
// the pinhole core's), lit from straight above so only their top faces are bright: the side faces
// get no light and nothing else is in the world, so each blob is one flat, evenly lit square.
Capture simulate_cubes(const CameraModel& placement, const std::string& name) {
  // The keyframe below: at (0, 0, h) looking down with image up = world +y, so camera x = world x,
  // camera y = world -y, camera z = world -z.
  std::vector<Vec3> positions;
  for (int row = 0; row < kRows; ++row)
    for (int column = 0; column < kColumns; ++column) {
      const Vec2 pixel{kBorderPx + column * (kWidth - 1.0 - 2 * kBorderPx) / (kColumns - 1),
                       kBorderPx + row * (kHeight - 1.0 - 2 * kBorderPx) / (kRows - 1)};
      const Vec3 ray = *placement.unproject(pixel);
      const double t = (kCameraHeightM - kTopM) / ray[2];
      positions.push_back({t * ray[0], -t * ray[1], 0.0});
    }
  std::string scene = fmt::format(R"(description = "lens acceptance: {} cubes lit from above, through a strong lens"
[camera]
lensmodel = "LENSMODEL_OPENCV8"
intrinsics = {}
width = {}
height = {}
pixel_format = "RGB24"
exposure_ms = 4.0
[camera.sensor]
noise = false
sensitivity = 250.0   # the top faces (radiance 0.8) at 0.8 of full scale
[render]
samples_per_pixel = 16
frames = 1
[[trajectory.keyframe]]
position = [0, 0, {}]
look_at = [0, 0, 0]
up = [0, 1, 0]
[[light]]
kind = "directional"
direction = [0, 0, 1]
irradiance = 3.141592653589793   # radiance of the top faces = albedo
)",
                                  positions.size(), kIntrinsics, kWidth, kHeight, kCameraHeightM);
  for (size_t i = 0; i < positions.size(); ++i)
    scene += fmt::format(
        "[[object]]\nname = \"cube{}\"\nshape = \"mesh\"\nmesh = \"builtin:cube\"\nmesh_scale = {}\nposition = [{:.17g}, "
        "{:.17g}, 0.0]\nalbedo = [0.8, 0.8, 0.8]\n",
        i, kCubeScale, positions[i][0], positions[i][1]);
  const sim::SimScene sim_scene = sim::parse_sim_scene(scene, name + ".toml", ARPIPE_SOURCE_DIR);
  const std::filesystem::path dir =
      std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / fmt::format("lens_matched_{}_{}", name, getpid());
  std::filesystem::remove_all(dir);
  sim::SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  const auto start = std::chrono::steady_clock::now();
  sim::simulate(sim_scene, options);
  Capture capture;
  capture.simulate_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RecordingReader reader(dir);
  reader.read(0, capture.frame);
  capture.T_cam_world = reader.ground_truth().at(0).T_cam_world_mid;
  capture.cube_positions = positions;
  std::filesystem::remove_all(dir);
  return capture;
}

// Cubes placed on the lens image's grid (for "map" and "vertex") and on the pinhole core's (for
// "undistort", whose picture is the core's), simulated once each.
const Capture& lens_grid_capture() {
  static const Capture capture = simulate_cubes(lens(), "lens_grid");
  return capture;
}
const Capture& core_grid_capture() {
  static const Capture capture = simulate_cubes(CameraModel::pinhole(400, 400, 322.3, 236.8, kWidth, kHeight), "core_grid");
  return capture;
}

StageHarness& harness() {
  static StageHarness instance;
  return instance;
}

// The same cubes as virtual objects: white, unlit sides, lit top (Lambert with the light straight
// above), so the drawn picture is bright exactly where the simulator's is.
Config cubes_config(const Capture& capture, const std::string& lens_mode) {
  Config config;
  config.render.objects.clear();
  for (const Vec3& position : capture.cube_positions) {
    SceneObject object;
    object.mesh = "builtin:cube";
    object.scale = kCubeScale;
    object.position_m = position;
    object.color = {1, 1, 1};
    config.render.objects.push_back(object);
  }
  config.render.light_direction = {0, 0, 1};
  config.render.light_color = {1, 1, 1};
  config.render.ambient = {0, 0, 0};
  config.render.msaa_samples = 4;
  config.render.lens = *choice_value(kLensModeNames, lens_mode);
  return config;
}

// Runs the stages on `frame`; Tracking draws the cubes, Lost leaves only the camera picture.
FrameContext run_stages(const Frame& frame, const SE3& T_cam_world, TrackState state) {
  FrameContext ctx = make_context(frame, std::make_shared<const CameraModel>(lens()), T_cam_world, state);
  harness().process(ctx);
  return ctx;
}

// Intensity-weighted centroid (linear light, mean of R, G, B) of the window around `around`.
std::optional<Vec2> centroid(const Frame& rgb, const Vec2& around) {
  double sum = 0, sum_x = 0, sum_y = 0;
  const int cx = int(std::lround(around[0])), cy = int(std::lround(around[1]));
  for (int y = std::max(0, cy - kWindowPx); y <= std::min(kHeight - 1, cy + kWindowPx); ++y)
    for (int x = std::max(0, cx - kWindowPx); x <= std::min(kWidth - 1, cx + kWindowPx); ++x) {
      const uint8_t* p = rgb.data.data() + size_t(y) * rgb.bytes_per_line + size_t(x) * 3;
      const double w = (decode_srgb(p[0] / 255.0) + decode_srgb(p[1] / 255.0) + decode_srgb(p[2] / 255.0)) / 3;
      sum += w, sum_x += w * x, sum_y += w * y;
    }
  if (sum < 50) return std::nullopt;  // a 25 px square of value ~0.8 sums to ~500
  return Vec2{sum_x / sum, sum_y / sum};
}

struct Agreement {
  double max_px = 0;
  double mean_px = 0;
  double corner_max_px = 0;  // over the four corner blobs
};

// Compares the blobs of `real` and `virtual_picture` around each cube's top face as `seen_by`
// projects it; every blob must be found in both.
Agreement compare_blobs(const Capture& capture, const Frame& real, const Frame& virtual_picture,
                        const CameraModel& seen_by, const std::string& label) {
  Agreement agreement;
  for (size_t i = 0; i < capture.cube_positions.size(); ++i) {
    const Vec3 top = capture.cube_positions[i] + Vec3{0, 0, kTopM};
    const std::optional<Vec2> expected = seen_by.project(capture.T_cam_world * top);
    EXPECT_TRUE(expected.has_value());
    if (!expected) continue;
    const std::optional<Vec2> a = centroid(real, *expected), b = centroid(virtual_picture, *expected);
    EXPECT_TRUE(a && b) << label << ": cube " << i << " near (" << (*expected)[0] << ", " << (*expected)[1]
                        << ") is missing from the " << (a ? "virtual" : "simulated") << " picture";
    if (!a || !b) continue;
    const double error = std::hypot((*a)[0] - (*b)[0], (*a)[1] - (*b)[1]);
    agreement.max_px = std::max(agreement.max_px, error);
    agreement.mean_px += error / double(capture.cube_positions.size());
    const size_t column = i % kColumns, row = i / kColumns;
    const bool corner = (column == 0 || column == kColumns - 1) && (row == 0 || row == kRows - 1);
    if (corner) agreement.corner_max_px = std::max(agreement.corner_max_px, error);
  }
  std::cout << label << ": simulated vs virtual top-face centroids over " << capture.cube_positions.size()
            << " cubes: max " << agreement.max_px << " px, mean " << agreement.mean_px << " px, corners max "
            << agreement.corner_max_px << " px (simulation " << capture.simulate_seconds << " s)\n";
  ::testing::Test::RecordProperty(label + "_max_px", fmt::format("{:.4f}", agreement.max_px));
  ::testing::Test::RecordProperty(label + "_mean_px", fmt::format("{:.4f}", agreement.mean_px));
  return agreement;
}

Frame black_frame() { return Frame::allocate(PixelFormat::RGB24, kWidth, kHeight); }

// Median render-stage time over three more frames of the same view (llvmpipe; not asserted).
double median_render_ms(const Frame& frame, const SE3& T_cam_world) {
  std::vector<double> ms;
  for (int run = 0; run < 3; ++run) {
    const FrameContext ctx = run_stages(frame, T_cam_world, TrackState::Tracking);
    if (const StageTiming* timing = find_timing(ctx, "render")) ms.push_back(timing->ms);
  }
  std::sort(ms.begin(), ms.end());
  return ms.empty() ? 0 : ms[ms.size() / 2];
}

// The lens image's picture of the cubes drawn by the stages, compared with the simulator's frame.
Agreement drawn_through_the_lens(const std::string& lens_mode, double canvas_scale = Config().render.lens_canvas_scale) {
  const Capture& capture = lens_grid_capture();
  Config config = cubes_config(capture, lens_mode);
  config.render.lens_canvas_scale = canvas_scale;
  harness().configure(config);
  const FrameContext ctx = run_stages(black_frame(), capture.T_cam_world, TrackState::Tracking);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  EXPECT_EQ(ctx.output_camera_model->lensmodel(), "LENSMODEL_OPENCV8");
  const std::string label = lens_mode == "map" ? fmt::format("map (canvas scale {:g})", canvas_scale) : lens_mode;
  const Agreement agreement = compare_blobs(capture, capture.frame, ctx.output, lens(), label);
  std::cout << label << ": render stage " << median_render_ms(black_frame(), capture.T_cam_world)
            << " ms per frame (median of 3; 35 cubes over the whole image)\n";
  return agreement;
}

TEST(LensMatchedRendering, MapModePutsVirtualPointsOnTheirRealCounterpartsEverywhere) {
  const Agreement agreement = drawn_through_the_lens("map");
  // Issue 5's criterion: within 0.25 px everywhere in the image, corners included.
  EXPECT_LE(agreement.max_px, 0.25);
}

TEST(LensMatchedRendering, MapModeCanvasScaleTradesAccuracyForCost) {
  // Measured, not asserted: 4x multisampling leaves a straight edge up to 1/8 canvas pixel off,
  // and the cubes' top faces are squares aligned with the canvas's axes (the worst case), so
  // their centroids move by up to 0.18 / scale px; the fill grows with the scale's square.
  for (const double scale : {1.0, 2.0}) drawn_through_the_lens("map", scale);
}

TEST(LensMatchedRendering, VertexModePutsVirtualPointsOnTheirRealCounterpartsEverywhere) {
  // Exact at the vertices; the cube's 8 x 8 grid per face keeps the chords between them within
  // a few hundredths of a pixel of the bent edges, so the same criterion holds.
  const Agreement agreement = drawn_through_the_lens("vertex");
  EXPECT_LE(agreement.max_px, 0.25);
}

TEST(LensMatchedRendering, UndistortModePutsVirtualPointsOnTheUndistortedRealOnes) {
  const Capture& capture = core_grid_capture();
  harness().configure(cubes_config(capture, "undistort"));
  // The real cubes: the simulator's frame undistorted by the composite stage (nothing drawn).
  const FrameContext real = run_stages(capture.frame, capture.T_cam_world, TrackState::Lost);
  EXPECT_FALSE(real.virtual_layer_drawn);
  // The virtual ones, drawn pinhole over a black frame (black undistorts to black).
  const FrameContext drawn = run_stages(black_frame(), capture.T_cam_world, TrackState::Tracking);
  EXPECT_TRUE(drawn.virtual_layer_drawn);
  for (const FrameContext* ctx : {&real, &drawn}) {
    ASSERT_NE(ctx->output_camera_model, nullptr);
    EXPECT_EQ(ctx->output_camera_model->lensmodel(), "LENSMODEL_PINHOLE");
    EXPECT_EQ(ctx->output_camera_model->intrinsics(), (std::vector<double>{400, 400, 322.3, 236.8}));
  }
  const CameraModel core = CameraModel::pinhole(400, 400, 322.3, 236.8, kWidth, kHeight);
  const Agreement agreement = compare_blobs(capture, real.output, drawn.output, core, "undistort");
  EXPECT_LE(agreement.max_px, 0.25);
}

}  // namespace
}  // namespace arpipe
