// A virtual object's shadow in each eye of a stereo panorama, against the simulator: an
// omnidirectional-stereo pair of a table under a sun, and the same pair with a virtual cube on the
// table (the simulator's ground-truth composite, cube and shadow ray-traced). Both pairs are seen
// through the panorama source's two eyes; the cube drawn live over the first, with its shadow on
// the catcher, must darken the table where the truth's shadow does in each eye, so that the
// shadow has the background's disparity (issue 23: shadows of the virtual objects in stereo).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/proxy_comparison.h"
#include "capture/panorama/panorama_source.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/config/config.h"
#include "core/track/tag_tracker.h"
#include "render/gl_stages.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

constexpr int kEyeWidth = 2048, kEyeHeight = 1024;
constexpr int kViewWidth = 1280, kViewHeight = 720;
constexpr double kViewHfovDeg = 50;
const Vec3 kViewpoint{0.0, 0.0, 0.5};
const Vec3 kCube{0.0, 0.45, 0.0};       // a 12 cm cube standing on the table, ahead and below
const Vec3 kToSun{0.40, -0.30, 0.866};  // its shadow falls ahead, to the left of it
constexpr double kSunIrradiance = 4.0, kSky = 0.3;
constexpr double kYawDeg = -4.0, kPitchDeg = -42.0;  // at the cube and its shadow

fs::path work_dir() {
  static const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / fmt::format("panorama_stereo_shadow_{}", getpid());
  return dir;
}

// The ODS pair (left eye on top) of the table, and of the table with the virtual cube: two PNGs.
struct Pairs {
  fs::path table, with_cube;
};

fs::path write_png(const fs::path& recording, const fs::path& file) {
  const RecordingReader reader(recording);
  Frame frame;
  reader.read(0, frame);
  cv::Mat bgr;
  cv::cvtColor(cv::Mat(frame.height, frame.width, CV_8UC3, frame.data.data(), frame.bytes_per_line), bgr, cv::COLOR_RGB2BGR);
  cv::imwrite(file.string(), bgr);
  return file;
}

const Pairs& pairs() {
  static const Pairs made = [] {
    const Vec3 sun = normalized(kToSun);
    const std::string scene = fmt::format(
        "[camera]\nlensmodel = \"LENSMODEL_LONLAT\"\nintrinsics = [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n"
        "width = {}\nheight = {}\npixel_format = \"RGB24\"\nexposure_ms = 4.0\n"
        "[camera.stereo]\nlayout = \"tb\"\nipd_m = 0.064\npole_merge_from_deg = 60\npole_merge_to_deg = 75\n"
        "[camera.sensor]\nnoise = false\nresponse = \"linear\"\n[render]\nsamples_per_pixel = 4\nframes = 1\nseed = 1\n"
        "[environment]\nradiance = [{}, {}, {}]\n"
        "[trajectory]\nkind = \"keyframes\"\n[[trajectory.keyframe]]\ntime_s = 0\nposition = [{:.17g}, {:.17g}, {:.17g}]\n"
        "look_at = [{:.17g}, {:.17g}, {:.17g}]\n"
        "[[object]]\nname = \"table\"\nposition = [0, 0, 0]\nwidth_m = 4.0\nheight_m = 4.0\nalbedo = [0.5, 0.5, 0.5]\n"
        "[[object]]\nname = \"cube\"\nshape = \"mesh\"\nmesh = \"builtin:cube\"\nmesh_scale = 2.0\n"
        "position = [{:.17g}, {:.17g}, {:.17g}]\nalbedo = [0.8, 0.3, 0.1]\nvirtual = true\n"
        "[[light]]\nname = \"sun\"\ndirection = [{:.17g}, {:.17g}, {:.17g}]\nirradiance = {}\nangular_diameter_deg = 1.0\n",
        kEyeWidth / (2 * kPi), kEyeHeight / kPi, (kEyeWidth - 1) / 2.0, (kEyeHeight - 1) / 2.0, kEyeWidth, kEyeHeight, kSky,
        kSky, kSky, kViewpoint[0], kViewpoint[1], kViewpoint[2], kViewpoint[0], kViewpoint[1] + 1, kViewpoint[2], kCube[0],
        kCube[1], kCube[2], sun[0], sun[1], sun[2], kSunIrradiance);
    const fs::path out = work_dir() / "ods";
    fs::remove_all(out);
    sim::SimulateOptions options;
    options.out_dir = out;
    sim::simulate(sim::parse_sim_scene(scene, "ods-shadow.toml", ARPIPE_SOURCE_DIR), options);
    return Pairs{write_png(out, work_dir() / "table.png"),
                 write_png(out / sim::kGroundTruthCompositeDir, work_dir() / "with-cube.png")};
  }();
  return made;
}

Config stereo_config(const fs::path& panorama, bool shadows) {
  Config config;
  config.source.type = SourceType::Panorama;
  config.source.pacing = ReplayPacing::Fast;
  PanoramaConfig& p = config.source.panorama;
  p.file = panorama;
  p.layout = PanoramaLayout::EquirectTopBottom;
  p.position_m = kViewpoint;
  p.view.width = kViewWidth;
  p.view.height = kViewHeight;
  p.view.hfov_rad = kViewHfovDeg * kDeg;
  p.view.yaw_rad = kYawDeg * kDeg;
  p.view.pitch_rad = kPitchDeg * kDeg;
  p.view.frames = 1;
  SceneObject cube;
  cube.mesh = "builtin:cube";
  cube.scale = 2;
  cube.position_m = kCube;
  cube.prt = ObjectPrt::Off;
  cube.color = {0.8, 0.3, 0.1};
  config.render.objects = {cube};
  // The sun as the fixed light: its irradiance over pi against the sky's radiance (only their ratio
  // matters to the catcher), with its disc; the table is the catcher.
  config.render.light_direction = normalized(kToSun);
  config.render.light_color = {kSunIrradiance / kPi, kSunIrradiance / kPi, kSunIrradiance / kPi};
  config.render.ambient = {kSky, kSky, kSky};
  config.render.shadows.method = shadows ? ShadowMethod::Pcss : ShadowMethod::Off;
  config.render.shadows.light_angular_diameter_deg = 1.0;
  config.render.shadows.receiver_height_m = 0;
  config.render.shadows.ground_albedo = 0;  // the simulator traces no light between surfaces
  config.render.shadows.sky_occlusion = true;  // the cube hides sky from the table beside it
  config.render.blur.method = BlurMethod::Off;
  config.light.response = CameraResponse::linear();  // the simulated sensor's
  return config;
}

// Per eye: the grey view of the source's frame, and the composited frame and layer alpha when drawn.
struct EyeView {
  cv::Mat background, composite;
  std::vector<float> alpha;
};
std::array<EyeView, 2> both_eyes(const Config& config, bool draw) {
  static std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  PanoramaSource source(config.source);
  TagTracker tracker;
  tracker.configure(config);
  for (auto& stage : stages) stage->configure(config);
  const auto grey = [](const Frame& f) {
    cv::Mat g;
    cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC3, const_cast<uint8_t*>(f.data.data()), f.bytes_per_line), g,
                 cv::COLOR_RGB2GRAY);
    g.convertTo(g, CV_64F);
    return g;
  };
  std::array<EyeView, 2> out;
  for (size_t eye = 0; eye < 2; ++eye) {
    FrameContext ctx;
    EXPECT_EQ(source.next(ctx.camera), SourceStatus::Frame);
    out[eye].background = grey(ctx.camera);
    if (!draw) continue;
    ctx.camera_model = source.camera_model();
    tracker.process(ctx);
    for (auto& stage : stages) stage->process(ctx);
    EXPECT_TRUE(ctx.virtual_layer_drawn);
    if (ctx.virtual_layer_drawn) out[eye].alpha = bench::layer_alpha(ctx.virtual_layer);
    out[eye].composite = grey(ctx.output.empty() ? ctx.camera : ctx.output);
  }
  return out;
}

// The centroid of the table's shadow: the pixels the cube does not cover (its coverage grown by
// 3 px) that are darker than the table by more than half the darkest's darkening (1 - picture /
// table), so that neither the two renderers' shadow depths nor the ray tracer's faint darkening
// of the sky's occlusion round the cube move it.
cv::Point2d shadow_centroid(const cv::Mat& picture, const cv::Mat& table, const std::vector<float>& cube_alpha) {
  cv::Mat cube(kViewHeight, kViewWidth, CV_8U);
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u) cube.at<uint8_t>(v, u) = cube_alpha[size_t(v) * kViewWidth + size_t(u)] > 0 ? 255 : 0;
  cv::dilate(cube, cube, cv::Mat::ones(7, 7, CV_8U));
  cv::Mat dark(kViewHeight, kViewWidth, CV_64F, cv::Scalar(0));
  double darkest = 0;
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u) {
      if (cube.at<uint8_t>(v, u) || table.at<double>(v, u) < 8) continue;
      dark.at<double>(v, u) = 1 - picture.at<double>(v, u) / table.at<double>(v, u);
      darkest = std::max(darkest, dark.at<double>(v, u));
    }
  double count = 0, x = 0, y = 0;
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u)
      if (dark.at<double>(v, u) > 0.5 * darkest) ++count, x += u, y += v;
  EXPECT_GT(count, 500) << "no shadow in view";
  return {x / count, y / count};
}

TEST(PanoramaStereoShadow, AVirtualCubesShadowLiesWhereTheRayTracedOneDoesInEachEye) {
  // The cube's coverage alone (shadows off), to leave its own pixels out of the shadow.
  const std::array<EyeView, 2> cube = both_eyes(stereo_config(pairs().table, false), true);
  const std::array<EyeView, 2> ours = both_eyes(stereo_config(pairs().table, true), true);
  const std::array<EyeView, 2> truth = both_eyes(stereo_config(pairs().with_cube, false), false);
  std::array<cv::Point2d, 2> drawn, traced;
  for (size_t eye = 0; eye < 2; ++eye) {
    ASSERT_EQ(cube[eye].alpha.size(), size_t(kViewWidth) * kViewHeight);
    ASSERT_FALSE(ours[eye].composite.empty());
    drawn[eye] = shadow_centroid(ours[eye].composite, ours[eye].background, cube[eye].alpha);
    traced[eye] = shadow_centroid(truth[eye].background, ours[eye].background, cube[eye].alpha);
    if (getenv("ARPIPE_TEST_VERBOSE")) {
      cv::imwrite((work_dir() / fmt::format("ours{}.png", eye)).string(), ours[eye].composite);
      cv::imwrite((work_dir() / fmt::format("truth{}.png", eye)).string(), truth[eye].background);
    }
    std::printf("%s eye: shadow at (%.2f, %.2f) drawn, (%.2f, %.2f) ray-traced\n", eye == 0 ? "left" : "right",
                drawn[eye].x, drawn[eye].y, traced[eye].x, traced[eye].y);
  }
  const cv::Point2d drawn_disparity = drawn[0] - drawn[1], traced_disparity = traced[0] - traced[1];
  std::printf("shadow disparity: %.3f, %.3f px drawn; %.3f, %.3f px ray-traced\n", drawn_disparity.x, drawn_disparity.y,
              traced_disparity.x, traced_disparity.y);
  // The disparity, what stereo shows of depth (about 141 px here: a shadow drawn through the mono
  // projection would have none), within the proxies' bar of 0.5 px; each eye's shadow within 1 px
  // (its penumbra is PCSS's, not the ray tracer's). Measured at the commit that added it: 0.22 px
  // in the left eye, 0.11 in the right, the disparities 0.22 px apart.
  EXPECT_LE(cv::norm(drawn_disparity - traced_disparity), 0.5);
  for (size_t eye = 0; eye < 2; ++eye) EXPECT_LE(cv::norm(drawn[eye] - traced[eye]), 1.0) << "eye " << eye;
}

}  // namespace
}  // namespace arpipe
