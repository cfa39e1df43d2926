// Motion blur and rolling shutter of the virtual layer through the render and composite stages:
// a white unlit cube over a black camera frame, so each output pixel decodes to the layer's alpha
// (its coverage over the exposure), checked against the analytic blur of the sharp render, and
// zero motion against the no-blur path byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "core/motion/image_motion.h"
#include "render_test_support.h"

namespace arpipe {
namespace {

using namespace render_test;

constexpr int kWidth = 320, kHeight = 240;
constexpr double kFx = 300.0;
constexpr int64_t kExposureNs = 10'000'000;
const std::vector<std::string> kBlurMethods{"accumulate", "intraframe-warp", "velocity"};

Config white_cube_config(const std::string& blur_method, int samples = 0, double min_motion_px = 0.5) {
  Config config;
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:cube";
  config.render.objects[0].scale = 2.0;  // 12 cm
  config.render.objects[0].color = {1, 1, 1};
  config.render.ambient = {1, 1, 1};  // unlit: premultiplied colour = alpha
  config.render.light_color = {0, 0, 0};
  const std::optional<BlurMethod> method = choice_value(kBlurMethodNames, blur_method);
  EXPECT_TRUE(method.has_value()) << blur_method;
  config.render.blur.method = method.value_or(BlurMethod::Off);
  config.render.blur.samples = samples;
  config.render.blur.min_motion_px = min_motion_px;
  return config;
}

std::shared_ptr<const CameraModel> pinhole_camera() {
  return std::make_shared<const CameraModel>(CameraModel::pinhole(kFx, kFx, 159.5, 119.5, kWidth, kHeight));
}

// Straight down onto the cube from 0.6 m: its top face is a square of about 60 px.
SE3 overhead_pose() { return look_at({0.0, -0.001, 0.72}, {0.0, 0.0, 0.0}); }

// The camera turns about its own y axis by `pan_rad` over the exposure (a pan: the picture moves
// sideways by about fx * pan_rad at the centre), the middle of it at the frame's pose; rows are
// read out over readout_ns (0: global shutter).
ShutterMotion pan_motion(const SE3& mid, double pan_rad, int64_t readout_ns = 0) {
  ShutterMotion motion;
  motion.state = MotionState::Interpolated;
  motion.timing = {0, kExposureNs, readout_ns, kHeight, false};
  motion.pose_time_ns = motion.timing.mid_ns();
  const double half_span = 0.5 * pan_rad * double(kExposureNs + readout_ns) / double(kExposureNs);
  motion.T_cam_world_start = SE3(rotation_from_vector({0, -half_span, 0}), {0, 0, 0}) * mid;
  motion.T_cam_world_mid = mid;
  motion.T_cam_world_end = SE3(rotation_from_vector({0, half_span, 0}), {0, 0, 0}) * mid;
  return motion;
}

struct Harness {
  StageHarness stages;
  Config configured;
  bool has_config = false;
  void configure(const Config& config) {
    if (has_config && config == configured) return;
    stages.configure(config);
    configured = config;
    has_config = true;
  }
};
Harness& harness() {
  static Harness instance;
  return instance;
}

Frame black_frame() {
  Frame frame = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  std::fill(frame.data.begin(), frame.data.end(), uint8_t{0});
  return frame;
}

FrameContext run(const Config& config, const ShutterMotion& motion) {
  harness().configure(config);
  FrameContext ctx = make_context(black_frame(), pinhole_camera(), motion.valid() ? motion.T_cam_world_mid : overhead_pose());
  ctx.motion = motion;
  if (motion.valid())
    ctx.motion.max_image_motion_px = max_image_motion_px(motion, *ctx.camera_model, {{0, 0, 0.12}, {0.06, 0.06, 0.12}});
  harness().stages.process(ctx);
  return ctx;
}

// The layer's alpha at every pixel, decoded from the red channel (white object, black frame).
std::vector<double> alpha_of(const FrameContext& ctx) {
  std::vector<double> alpha(size_t(kWidth) * kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      alpha[size_t(y) * kWidth + x] = decode_srgb(ctx.output.data[size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3] / 255.0);
  return alpha;
}

std::vector<double> row_of(const std::vector<double>& alpha, int y) {
  return {alpha.begin() + ptrdiff_t(y) * kWidth, alpha.begin() + ptrdiff_t(y + 1) * kWidth};
}

// The sharp row moved through every offset in [-L/2, L/2] and averaged: a box filter of length L
// (sub-pixel offsets by linear interpolation, 64 steps per pixel of L).
std::vector<double> box_blurred(const std::vector<double>& row, double length) {
  const int steps = std::max(1, int(std::ceil(length * 64)));
  std::vector<double> out(row.size(), 0.0);
  for (int s = 0; s < steps; ++s) {
    const double offset = length * ((s + 0.5) / steps - 0.5);
    for (int x = 0; x < int(row.size()); ++x) {
      const double from = x - offset;
      const int x0 = int(std::floor(from));
      const double w = from - x0;
      const auto at = [&](int i) { return i >= 0 && i < int(row.size()) ? row[size_t(i)] : 0.0; };
      out[size_t(x)] += ((1 - w) * at(x0) + w * at(x0 + 1)) / steps;
    }
  }
  return out;
}

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

double centroid_x(const std::vector<double>& row) {
  double mass = 0, moment = 0;
  for (size_t x = 0; x < row.size(); ++x) {
    mass += row[x];
    moment += row[x] * double(x);
  }
  return mass > 0 ? moment / mass : -1;
}

TEST(MotionBlur, ZeroMotionIsByteIdenticalToTheNoBlurPath) {
  const ShutterMotion still = pan_motion(overhead_pose(), 0.0);
  const FrameContext sharp = run(white_cube_config("off"), still);
  ASSERT_TRUE(sharp.virtual_layer_drawn);
  for (const std::string& method : kBlurMethods) {
    const FrameContext blurred = run(white_cube_config(method), still);
    ASSERT_TRUE(blurred.virtual_layer_drawn) << method;
    EXPECT_EQ(blurred.blur_method, "off") << method << ": below min_motion_px the frame is drawn sharp";
    EXPECT_TRUE(blurred.output.data == sharp.output.data) << method;
  }
}

TEST(MotionBlur, ForcedBlurOfZeroMotionReproducesTheSharpLayer) {
  // With min_motion_px = 0 every method runs on a still camera: all its samples are the sharp
  // layer, so the result differs by rounding only (half-float sums and bilinear taps at texel
  // centres): at most 1 of 255 per channel.
  const ShutterMotion still = pan_motion(overhead_pose(), 0.0);
  const FrameContext sharp = run(white_cube_config("off"), still);
  for (const std::string& method : kBlurMethods) {
    const FrameContext blurred = run(white_cube_config(method, 8, 0.0), still);
    ASSERT_EQ(blurred.blur_method, method);
    int worst = 0;
    for (size_t i = 0; i < sharp.output.data.size(); ++i)
      worst = std::max(worst, std::abs(int(blurred.output.data[i]) - int(sharp.output.data[i])));
    EXPECT_LE(worst, 1) << method;
  }
}

// The image motion of the cube's top centre over the exposure, from the poses alone.
double predicted_shift_px(const ShutterMotion& motion) {
  const CameraModel camera = *pinhole_camera();
  const Vec2 start = *camera.project(motion.T_cam_world_start * Vec3{0, 0, 0.12});
  const Vec2 end = *camera.project(motion.T_cam_world_end * Vec3{0, 0, 0.12});
  return end[0] - start[0];
}

class BlurWidth : public ::testing::TestWithParam<std::tuple<std::string, double>> {};

TEST_P(BlurWidth, MatchesThePredictedImageMotion) {
  const auto& [method, shift_px] = GetParam();
  const ShutterMotion motion = pan_motion(overhead_pose(), shift_px / kFx);
  const double predicted = predicted_shift_px(motion);
  ASSERT_NEAR(predicted, shift_px, 0.05 * shift_px) << "the pan moves the picture by fx * angle near the centre";

  const std::vector<double> sharp = alpha_of(run(white_cube_config("off"), motion));
  const FrameContext ctx = run(white_cube_config(method), motion);
  ASSERT_EQ(ctx.blur_method, method);
  EXPECT_GE(ctx.blur_samples, method == "intraframe-warp" ? int(std::lround(shift_px)) : int(std::ceil(shift_px)));
  const std::vector<double> blurred = alpha_of(ctx);
  const int y = kHeight / 2;
  const std::vector<double> sharp_row = row_of(sharp, y);
  const std::vector<double> expected = box_blurred(sharp_row, predicted);
  const std::vector<double> got = row_of(blurred, y);
  // The sharp row blurred by the predicted motion: the methods sample the motion (one sample per
  // pixel of it gives steps of 1/n in the ramps) and the seed's affine warps approximate the
  // perspective of a pan; 0.08 of full coverage is about 1 px of edge position on a ramp of L px.
  EXPECT_LT(max_abs_difference(got, expected), 0.08) << method << " at " << shift_px << " px";
  // A time average moves coverage, it does not make or lose it: 2 % (8-bit sRGB decode).
  const double mass_sharp = std::accumulate(sharp_row.begin(), sharp_row.end(), 0.0);
  const double mass_blurred = std::accumulate(got.begin(), got.end(), 0.0);
  EXPECT_NEAR(mass_blurred, mass_sharp, 0.02 * mass_sharp) << method;
  // The blur is centred on the mid-exposure picture: 0.25 px.
  EXPECT_NEAR(centroid_x(got), centroid_x(sharp_row), 0.25) << method;
}

INSTANTIATE_TEST_SUITE_P(Methods, BlurWidth,
                         ::testing::Combine(::testing::Values("accumulate", "intraframe-warp", "velocity"),
                                            ::testing::Values(6.0, 24.0)));

TEST(MotionBlur, SkippedBelowTheThresholdAndReportedAbove) {
  const ShutterMotion slow = pan_motion(overhead_pose(), 0.3 / kFx);
  const FrameContext ctx_slow = run(white_cube_config("intraframe-warp"), slow);
  EXPECT_EQ(ctx_slow.blur_method, "off");
  const ShutterMotion fast = pan_motion(overhead_pose(), 10.0 / kFx);
  const FrameContext ctx_fast = run(white_cube_config("intraframe-warp"), fast);
  EXPECT_EQ(ctx_fast.blur_method, "intraframe-warp");
  EXPECT_EQ(ctx_fast.blur_samples, 12) << "the thesis's rule: round(D) + 2 with D = 10 px";
}

TEST(MotionBlur, RollingShutterSkewsTheLayerLikeThePicture) {
  // A pan during a 30 ms readout: each row sees the cube later than the one above, so its
  // picture slants; drawn with each row's own pose it slants the same way.
  const int64_t readout_ns = 30'000'000;
  const double pan_rad = 40.0 / kFx;  // 40 px per exposure time (10 ms), 160 px over exposure + readout
  const ShutterMotion motion = pan_motion(overhead_pose(), pan_rad, readout_ns);
  const std::vector<double> alpha = alpha_of(run(white_cube_config("off"), motion));
  const CameraModel camera = *pinhole_camera();
  // Two rows through the top face, 40 rows apart.
  for (int y : {100, 140}) {
    const SE3 T_row = motion.T_cam_world_at_row(y);
    // Where the cube's top centre line lies in that row's picture: the centre of the face's span.
    const Vec2 centre = *camera.project(T_row * Vec3{0, 0, 0.12});
    const double got = centroid_x(row_of(alpha, y));
    EXPECT_NEAR(got, centre[0], 0.5) << "row " << y << " mid-pose centre " << camera.project(motion.T_cam_world_mid * Vec3{0, 0, 0.12}).value()[0];
  }
  const double skew = centroid_x(row_of(alpha, 140)) - centroid_x(row_of(alpha, 100));
  // pan_motion turns by pan_rad per exposure time: 40 px / 10 ms, over the 40/239 x 30 ms between the rows.
  const double expected_skew = 40.0 * (40.0 / (kHeight - 1)) * double(readout_ns) / double(kExposureNs);
  EXPECT_NEAR(skew, expected_skew, 0.5) << "pan speed x the readout time between the rows";

  // Without the correction the layer stays upright.
  Config upright = white_cube_config("off");
  upright.render.rolling_shutter = false;
  const std::vector<double> upright_alpha = alpha_of(run(upright, motion));
  EXPECT_NEAR(centroid_x(row_of(upright_alpha, 140)), centroid_x(row_of(upright_alpha, 100)), 0.1);
}

TEST(MotionBlur, HugeAndTinyMotionsStayBounded) {
  // A turn of 1.5 rad inside one exposure (the cube sweeps across and out of the picture) and one
  // of 1e-9 rad: every method draws, coverage stays in [0, 1] with nothing beyond the frame, and
  // the tiny one (forced past the threshold) is the sharp picture to 1/255.
  const std::vector<double> sharp = alpha_of(run(white_cube_config("off"), pan_motion(overhead_pose(), 0.0)));
  for (const std::string& method : kBlurMethods) {
    const FrameContext huge = run(white_cube_config(method), pan_motion(overhead_pose(), 1.5));
    ASSERT_TRUE(huge.virtual_layer_drawn) << method;
    EXPECT_EQ(huge.blur_method, method);
    const std::vector<double> alpha = alpha_of(huge);
    double mass = 0;
    for (double a : alpha) {
      EXPECT_GE(a, 0.0);
      EXPECT_LE(a, 1.0);
      mass += a;
    }
    const double sharp_mass = std::accumulate(sharp.begin(), sharp.end(), 0.0);
    // Spread over ~450 px of path, most of it outside the 320 px image: less than the sharp mass.
    EXPECT_LT(mass, sharp_mass) << method;
    EXPECT_GT(mass, 0.0) << method;

    const FrameContext tiny = run(white_cube_config(method, 0, 0.0), pan_motion(overhead_pose(), 1e-9));
    EXPECT_EQ(tiny.blur_method, method);
    EXPECT_LT(max_abs_difference(alpha_of(tiny), sharp), 1.0 / 255) << method;
  }
}

TEST(MotionBlur, APredictedPoseIsDrawnAndBlurred) {
  const ShutterMotion motion = pan_motion(overhead_pose(), 12.0 / kFx);
  harness().configure(white_cube_config("intraframe-warp"));
  FrameContext ctx = make_context(black_frame(), pinhole_camera(), motion.T_cam_world_mid, TrackState::Predicted);
  ctx.motion = motion;
  ctx.motion.max_image_motion_px = 12.0;
  ctx.pose.predicted_uncertainty_deg = 2.0;  // within the default render.max_predicted_uncertainty_deg (5)
  harness().stages.process(ctx);
  EXPECT_TRUE(ctx.virtual_layer_drawn);
  EXPECT_EQ(ctx.blur_method, "intraframe-warp");

  // Past the bound the object would stand visibly in the wrong place: not drawn, and said why.
  FrameContext uncertain = make_context(black_frame(), pinhole_camera(), motion.T_cam_world_mid, TrackState::Predicted);
  uncertain.motion = ctx.motion;
  uncertain.pose.predicted_uncertainty_deg = 10.0;
  harness().stages.process(uncertain);
  EXPECT_FALSE(uncertain.virtual_layer_drawn);
  const StageTiming* render = find_timing(uncertain, "render");
  ASSERT_NE(render, nullptr);
  EXPECT_EQ(render->skipped, "predicted pose too uncertain (10.0 > 5.0 deg)");
}

}  // namespace
}  // namespace arpipe
