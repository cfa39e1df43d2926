// Issue 23's stereo bar: a simulated omnidirectional-stereo panorama (the simulator's ODS pair,
// [camera.stereo]) of black balls under a bright sky, at every latitude from the horizon to the
// zenith and down towards the lower pole, seen through the panorama source's two eyes; a virtual
// ball drawn where each real one is must sit on it in each eye, so that its disparity is the
// background's, within 0.5 px in a 1280 x 720 view that magnifies the panorama 4.5 times.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/proxy_comparison.h"
#include "capture/panorama/panorama_source.h"
#include "capture/recording/recording_reader.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/config/config.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/glb_writer.h"
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
constexpr double kBallRadiusM = 0.05;
const Vec3 kViewpoint{0.2, -0.1, 1.5};

// Where each ball is seen from the viewpoint: azimuth (right of +y), elevation, distance.
struct Ball {
  double azimuth_deg, elevation_deg, distance_m;
  Vec3 centre() const {
    const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
    return kViewpoint + distance_m * Vec3{std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)};
  }
};
// The horizon, up through the pole merge (60 to 75 degrees) to the zenith, and down.
const Ball kBalls[] = {{0, 0, 0.8},     {45, 30, 1.5},   {90, 55, 0.8},   {135, 62, 1.5},  {180, 67.5, 0.8},
                       {225, 72, 1.5},  {270, 80, 0.8},  {0, 90, 1.2},    {315, -45, 0.8}, {100, -80, 1.0}};

// A black slab 2.4 m by 0.6 m, 0.5 m below the eye, from 0.3 to 0.9 m behind it (world -y): its
// far edge crosses the view looking back and down.
const Vec3 kSlabCentre = kViewpoint + Vec3{0, -0.6, -0.5};
constexpr double kSlabSize[2] = {2.4, 0.6};

fs::path work_dir() {
  static const fs::path dir = fs::path(ARPIPE_BINARY_DIR) / "test_tmp" / fmt::format("panorama_stereo_{}", getpid());
  return dir;
}

// The ODS pair (left eye on top) as a PNG, simulated once.
const fs::path& stereo_panorama() {
  static const fs::path png = [] {
    std::string scene = fmt::format(
        "[camera]\nlensmodel = \"LENSMODEL_LONLAT\"\nintrinsics = [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n"
        "width = {}\nheight = {}\npixel_format = \"RGB24\"\nexposure_ms = 4.0\n"
        "[camera.stereo]\nlayout = \"tb\"\nipd_m = 0.064\npole_merge_from_deg = 60\npole_merge_to_deg = 75\n"
        "[camera.sensor]\nnoise = false\nresponse = \"linear\"\n[render]\nsamples_per_pixel = 16\nframes = 1\nseed = 1\n"
        "[environment]\nradiance = [0.4, 0.4, 0.4]\n"
        "[trajectory]\nkind = \"keyframes\"\n[[trajectory.keyframe]]\ntime_s = 0\nposition = [{:.17g}, {:.17g}, {:.17g}]\n"
        "look_at = [{:.17g}, {:.17g}, {:.17g}]\n",
        kEyeWidth / (2 * kPi), kEyeHeight / kPi, (kEyeWidth - 1) / 2.0, (kEyeHeight - 1) / 2.0, kEyeWidth, kEyeHeight,
        kViewpoint[0], kViewpoint[1], kViewpoint[2], kViewpoint[0], kViewpoint[1] + 1, kViewpoint[2]);
    scene += fmt::format("[[object]]\nshape = \"plane\"\nwidth_m = {}\nheight_m = {}\nposition = [{:.17g}, {:.17g}, {:.17g}]\n"
                         "albedo = [0, 0, 0]\n",
                         kSlabSize[0], kSlabSize[1], kSlabCentre[0], kSlabCentre[1], kSlabCentre[2]);
    for (const Ball& ball : kBalls) {
      const Vec3 c = ball.centre();
      scene += fmt::format("[[object]]\nshape = \"sphere\"\nradius_m = {}\nposition = [{:.17g}, {:.17g}, {:.17g}]\nalbedo = [0, 0, 0]\n",
                           kBallRadiusM, c[0], c[1], c[2]);
    }
    const fs::path out = work_dir() / "ods";
    fs::remove_all(out);
    sim::SimulateOptions options;
    options.out_dir = out;
    sim::simulate(sim::parse_sim_scene(scene, "ods.toml", ARPIPE_SOURCE_DIR), options);
    const RecordingReader reader(out);
    Frame frame;
    reader.read(0, frame);
    EXPECT_EQ(frame.width, kEyeWidth);
    EXPECT_EQ(frame.height, 2 * kEyeHeight);
    cv::Mat bgr;
    cv::cvtColor(cv::Mat(frame.height, frame.width, CV_8UC3, frame.data.data(), frame.bytes_per_line), bgr, cv::COLOR_RGB2BGR);
    const fs::path file = work_dir() / "ods.png";
    cv::imwrite(file.string(), bgr);
    return file;
  }();
  return png;
}

Config stereo_config(const Ball& ball) {
  Config config;
  config.source.type = SourceType::Panorama;
  config.source.pacing = ReplayPacing::Fast;
  PanoramaConfig& panorama = config.source.panorama;
  panorama.file = stereo_panorama();
  panorama.layout = PanoramaLayout::EquirectTopBottom;
  panorama.position_m = kViewpoint;
  panorama.view.width = kViewWidth;
  panorama.view.height = kViewHeight;
  panorama.view.hfov_rad = kViewHfovDeg * kDeg;
  panorama.view.yaw_rad = ball.azimuth_deg * kDeg;
  panorama.view.pitch_rad = ball.elevation_deg * kDeg;
  panorama.view.frames = 1;
  // builtin:sphere is 3 cm in radius, standing on its origin.
  SceneObject object;
  object.mesh = "builtin:sphere";
  object.scale = kBallRadiusM / 0.03;
  object.position_m = ball.centre() - Vec3{0, 0, kBallRadiusM};
  object.prt = ObjectPrt::Off;
  config.render.objects = {object};
  config.render.shadows.method = ShadowMethod::Off;
  config.render.blur.method = BlurMethod::Off;
  return config;
}

// The alpha-weighted centroid of the virtual layer, and the darkness-weighted centroid of the
// background (the sky's level less the grey, over the sky's level) within `window_px` of it.
struct Centroids {
  cv::Point2d virtual_ball, background_ball;
};
Centroids centroids(const Frame& background, const std::vector<float>& alpha, double window_px) {
  Centroids out;
  double sum = 0, x = 0, y = 0;
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u) {
      const double a = alpha[size_t(v) * kViewWidth + size_t(u)];
      sum += a, x += a * u, y += a * v;
    }
  EXPECT_GT(sum, 100) << "the virtual ball is not in view";
  out.virtual_ball = {x / sum, y / sum};
  cv::Mat grey;
  cv::cvtColor(cv::Mat(background.height, background.width, CV_8UC3, const_cast<uint8_t*>(background.data.data()),
                       background.bytes_per_line),
               grey, cv::COLOR_RGB2GRAY);
  double sky = 0;
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u) sky = std::max(sky, double(grey.at<uint8_t>(v, u)));
  sum = x = y = 0;
  for (int v = 0; v < kViewHeight; ++v)
    for (int u = 0; u < kViewWidth; ++u) {
      if (std::hypot(u - out.virtual_ball.x, v - out.virtual_ball.y) > window_px) continue;
      const double w = (sky - grey.at<uint8_t>(v, u)) / sky;
      sum += w, x += w * u, y += w * v;
    }
  out.background_ball = {x / sum, y / sum};
  return out;
}

// The first time step's two frames (left eye, then right) through the source and the real stages:
// per eye, f(eye, background, ctx) once the layer is drawn.
template <class F>
void for_both_eyes(const Config& config, F f) {
  static std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  PanoramaSource source(config.source);
  TagTracker tracker;
  tracker.configure(config);
  for (auto& stage : stages) stage->configure(config);
  for (size_t eye = 0; eye < 2; ++eye) {
    FrameContext ctx;
    EXPECT_EQ(source.next(ctx.camera), SourceStatus::Frame);
    EXPECT_EQ(ctx.camera.meta.eye, eye == 0 ? Eye::Left : Eye::Right);
    const Frame background = ctx.camera;
    ctx.camera_model = source.camera_model();
    tracker.process(ctx);
    for (auto& stage : stages) stage->process(ctx);
    EXPECT_TRUE(ctx.virtual_layer_drawn);
    if (ctx.virtual_layer_drawn) f(eye, background, ctx);
  }
}

// Per eye (left, right), the two centroids of the ball's view through the source and the stages.
std::array<Centroids, 2> seen_by_both_eyes(const Config& config, const Ball& ball) {
  // The ball's radius in the view, and a window 1.6 times that about it (the balls near the
  // zenith are 10 degrees apart, 256 px here).
  const double focal_px = 0.5 * kViewWidth / std::tan(0.5 * kViewHfovDeg * kDeg);
  const double window_px = 1.6 * focal_px * kBallRadiusM / ball.distance_m;
  std::array<Centroids, 2> eyes;
  for_both_eyes(config, [&](size_t eye, const Frame& background, const FrameContext& ctx) {
    eyes[eye] = centroids(background, bench::layer_alpha(ctx.virtual_layer), window_px);
  });
  return eyes;
}

TEST(PanoramaStereo, AVirtualBallHasItsRealBallsDisparityAtEveryLatitude) {
  const double focal_px = 0.5 * kViewWidth / std::tan(0.5 * kViewHfovDeg * kDeg);
  for (const Ball& ball : kBalls) {
    const std::array<Centroids, 2> eyes = seen_by_both_eyes(stereo_config(ball), ball);
    const cv::Point2d real_disparity = eyes[0].background_ball - eyes[1].background_ball;
    const cv::Point2d virtual_disparity = eyes[0].virtual_ball - eyes[1].virtual_ball;
    std::printf("elevation %5.1f, %.1f m: disparity real %7.3f, %7.3f px, virtual %7.3f, %7.3f px; left eye off by %.3f px, right %.3f px\n",
                ball.elevation_deg, ball.distance_m, real_disparity.x, real_disparity.y, virtual_disparity.x,
                virtual_disparity.y, cv::norm(eyes[0].virtual_ball - eyes[0].background_ball),
                cv::norm(eyes[1].virtual_ball - eyes[1].background_ball));
    EXPECT_LE(cv::norm(virtual_disparity - real_disparity), 0.5) << "elevation " << ball.elevation_deg;
    for (const Centroids& eye : eyes)
      EXPECT_LE(cv::norm(eye.virtual_ball - eye.background_ball), 0.5) << "elevation " << ball.elevation_deg;
    // Below the pole merge the eyes see the ball apart: a disparity there, none above it.
    // (The eyes' rays part by 2 asin(r / rho) in azimuth, cos(elevation) of that on the view's sphere.)
    const double elevation = ball.elevation_deg * kDeg;
    const double expected_px = focal_px * std::cos(elevation) * 2 * std::asin(0.032 / (ball.distance_m * std::cos(elevation)));
    if (std::abs(ball.elevation_deg) <= 30) {
      EXPECT_NEAR(std::abs(real_disparity.x), expected_px, 0.1 * expected_px);
    }
    if (std::abs(ball.elevation_deg) >= 80) {
      EXPECT_LE(cv::norm(real_disparity), 0.5);
    }
  }
}

// Down each 32nd column, how far the virtual layer's edge (alpha crossing 0.5) lies from the real
// slab's far edge in the background (where the sky gives way to the slab): mean and largest, px.
// alpha_falls: the layer's coverage ends at the edge going down (a floor behind the slab's proxy),
// else it starts there (the slab's virtual twin).
struct EdgeOffsets {
  double mean = 0, worst = 0;
};
EdgeOffsets edge_offsets(const Frame& background, const std::vector<float>& alpha, bool alpha_falls) {
  cv::Mat grey;
  cv::cvtColor(cv::Mat(background.height, background.width, CV_8UC3, const_cast<uint8_t*>(background.data.data()),
                       background.bytes_per_line),
               grey, cv::COLOR_RGB2GRAY);
  // The panorama is linear (its sensor's response), and the lookup interpolates its values, so
  // half the sky's value is where half a texel is slab.
  const auto linear = [&](int v, int u) { return double(grey.at<uint8_t>(v, u)); };
  const double sky = linear(0, kViewWidth / 2);
  const auto crossing = [](const auto& value, double level) -> double {
    for (int v = 1; v < kViewHeight; ++v)
      if (value(v) < level && value(v - 1) >= level) return v - 1 + (value(v - 1) - level) / (value(v - 1) - value(v));
    return NAN;
  };
  EdgeOffsets out;
  int columns = 0;
  for (int u = 16; u < kViewWidth; u += 32) {
    const double real = crossing([&](int v) { return linear(v, u); }, 0.5 * sky);
    const double drawn = crossing(
        [&](int v) {
          const double a = alpha[size_t(v) * kViewWidth + size_t(u)];
          return alpha_falls ? a : 1 - a;
        },
        0.5);
    EXPECT_TRUE(std::isfinite(real) && std::isfinite(drawn)) << "column " << u;
    if (!std::isfinite(real) || !std::isfinite(drawn)) continue;
    if (getenv("ARPIPE_TEST_VERBOSE")) std::printf("u %d: %.3f\n", u, drawn - real);
    out.mean += std::abs(drawn - real);
    out.worst = std::max(out.worst, std::abs(drawn - real));
    ++columns;
  }
  if (columns > 0) out.mean /= columns;
  return out;
}

// Both eyes' edge offsets, for a config looking at the slab's far edge.
std::array<EdgeOffsets, 2> slab_edge_in_both_eyes(const Config& config, bool alpha_falls) {
  std::array<EdgeOffsets, 2> out;
  for_both_eyes(config, [&](size_t eye, const Frame& background, const FrameContext& ctx) {
    out[eye] = edge_offsets(background, bench::layer_alpha(ctx.virtual_layer), alpha_falls);
  });
  return out;
}

const Ball kAtTheSlabsFarEdge{180, -35, 1.0};

TEST(PanoramaStereo, AProxyEdgeAcrossTheViewFollowsItsRealEdgeInEachEye) {
  // The slab as a proxy that hides a virtual floor 1 m below the eye: the floor's coverage ends
  // where the slab's far edge is in each eye's panorama (a long straight edge, which each eye's
  // offset bends; uploaded_objects.h cuts proxies for it: left uncut, as builtin:plane's 0.3 m
  // cells, the edge was 1.8 px off on average and 3.8 px at most, measured once).
  Config config = stereo_config(kAtTheSlabsFarEdge);
  // "auto": the 1:1 still is a top/bottom pair, and the render stage cuts the proxies when the
  // first eye's frame comes.
  config.source.panorama.layout = PanoramaLayout::Auto;
  SceneObject floor;
  floor.mesh = "builtin:plane";  // 6 cm across, scaled to 9.6 m
  floor.scale = 160;
  floor.position_m = kViewpoint + Vec3{0, 0, -1.0};
  floor.prt = ObjectPrt::Off;
  config.render.objects = {floor};
  SceneProxy slab;
  slab.name = "slab";
  slab.mesh = "builtin:plane";
  slab.size_m = {kSlabSize[0], kSlabSize[1], 0};
  slab.position_m = kSlabCentre;
  slab.roles = ProxyRoles{};
  slab.roles.occlude = true;
  config.render.proxies = {slab};
  const std::array<EdgeOffsets, 2> eyes = slab_edge_in_both_eyes(config, true);
  for (size_t eye = 0; eye < 2; ++eye) {
    std::printf("%s eye: the proxy's edge %.3f px from the real one on average, %.3f px at most\n",
                eye == 0 ? "left" : "right", eyes[eye].mean, eyes[eye].worst);
    EXPECT_LE(eyes[eye].mean, 0.5);
    EXPECT_LE(eyes[eye].worst, 1.0);
  }
}

TEST(PanoramaStereo, AVirtualObjectsLongEdgeFollowsItsRealEdgeInEachEye) {
  // The slab's virtual twin (two triangles 2.4 m by 0.6 m in a glTF file) drawn where the real
  // slab is: its coverage starts at the real far edge in each eye, the object cut for the eyes as
  // the proxies are. Uncut (two triangles), its 2.4 m edge is bent by each eye's offset, which the
  // rasteriser draws straight: 1.83 px off on average and 3.83 px at most, measured once at ca0938c.
  const fs::path glb = work_dir() / "slab.glb";
  {
    fs::create_directories(work_dir());
    const std::vector<uint8_t> bytes =
        encode_glb(*make_builtin_mesh("builtin:plane", {kSlabSize[0], kSlabSize[1], 0}, 1), "panorama_stereo_test");
    std::ofstream(glb, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }
  for (const PanoramaLayout layout : {PanoramaLayout::EquirectTopBottom, PanoramaLayout::Auto}) {
    Config config = stereo_config(kAtTheSlabsFarEdge);
    config.source.panorama.layout = layout;  // cut at setup, or on the first eye's frame
    SceneObject twin;
    twin.mesh = glb.string();
    twin.position_m = kSlabCentre;
    twin.prt = ObjectPrt::Off;
    config.render.objects = {twin};
    const std::array<EdgeOffsets, 2> eyes = slab_edge_in_both_eyes(config, false);
    for (size_t eye = 0; eye < 2; ++eye) {
      std::printf("%s eye (%s): the virtual slab's edge %.3f px from the real one on average, %.3f px at most\n",
                  eye == 0 ? "left" : "right", layout == PanoramaLayout::Auto ? "auto" : "top/bottom", eyes[eye].mean,
                  eyes[eye].worst);
      EXPECT_LE(eyes[eye].mean, 0.5);
      EXPECT_LE(eyes[eye].worst, 1.0);
    }
  }
}

TEST(PanoramaStereo, TheSeedsConstantEyeSeparationMissesNearThePole) {
  // The seed's viewer kept the eyes apart up to the pole: drawn so (pole merge at 90 degrees), the
  // virtual ball at 72 degrees parts from its real one by tens of pixels of disparity, so the
  // test above sees the taper.
  const Ball& ball = kBalls[5];
  ASSERT_EQ(ball.elevation_deg, 72);
  Config config = stereo_config(ball);
  config.source.panorama.pole_merge_from_rad = config.source.panorama.pole_merge_to_rad = kPi / 2;
  const std::array<Centroids, 2> eyes = seen_by_both_eyes(config, ball);
  const cv::Point2d real_disparity = eyes[0].background_ball - eyes[1].background_ball;
  const cv::Point2d virtual_disparity = eyes[0].virtual_ball - eyes[1].virtual_ball;
  std::printf("constant separation at 72 degrees: disparity real %.3f px, virtual %.3f px\n", real_disparity.x, virtual_disparity.x);
  EXPECT_GT(cv::norm(virtual_disparity - real_disparity), 20);
}

}  // namespace
}  // namespace arpipe
