// Shutter motion: the exposure window (the simulator's row timing), the pose track, the estimate
// from neighbouring poses against analytic constant-velocity motions, the image motion against
// its closed form, and the motion stage's states and skip reasons.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/motion/image_motion.h"
#include "core/motion/motion_stage.h"
#include "core/motion/pose_track.h"
#include "core/motion/shutter_motion.h"

namespace arpipe {
namespace {

constexpr int64_t kFrameNs = 33'333'333;  // 30 fps
constexpr int64_t kT0 = 5'000'000'000;

double angle_between(const SE3& a, const SE3& b) { return rotation_angle_between(a, b); }
double centre_distance(const SE3& a, const SE3& b) {
  return norm(a.inverse().translation() - b.inverse().translation());
}

// A camera turning about its own y axis at w rad/s while walking along world x at v m/s, 0.5 m in
// front of the anchor (looking down at it along world -z): constant velocity in the centre-line model.
struct SteadyCamera {
  double w = 2.0;  // rad/s
  double v = 0.3;  // m/s
  SE3 T_cam_world(int64_t t_ns) const {
    const double t = double(t_ns - kT0) * 1e-9;
    const Mat3 looking_down{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};  // camera z = world -z
    const SE3 T_world_cam(mat_mul(looking_down, rotation_from_vector({0, w * t, 0})), {v * t, 0, 0.5});
    return T_world_cam.inverse();
  }
};

FrameMetadata metadata(uint64_t frame, int64_t exposure_ns, int64_t readout_ns = 0) {
  FrameMetadata meta;
  meta.sequence = frame;
  meta.exposure_start_ns = kT0 + int64_t(frame) * kFrameNs;
  meta.exposure_ns = exposure_ns;
  meta.readout_ns = readout_ns;
  meta.frame_duration_ns = kFrameNs;
  return meta;
}

TEST(ShutterTiming, RowsFollowTheSimulatorsDefinition) {
  // docs/SIMULATOR.md: row r starts r/(height-1) x readout after row 0.
  const ShutterTiming t = shutter_timing(metadata(0, 2'000'000, 24'000'000), 481, 10'000'000);
  EXPECT_FALSE(t.fallback_exposure);
  EXPECT_EQ(t.row_start_ns(0), kT0);
  EXPECT_EQ(t.row_start_ns(480), kT0 + 24'000'000);
  EXPECT_EQ(t.row_start_ns(240), kT0 + 12'000'000);
  EXPECT_EQ(t.row_start_ns(1), kT0 + 50'000);
  EXPECT_EQ(t.row_mid_ns(240), kT0 + 13'000'000);
  EXPECT_EQ(t.mid_ns(), metadata(0, 2'000'000, 24'000'000).exposure_mid_ns());
  EXPECT_EQ(t.end_ns(), kT0 + 26'000'000);
  EXPECT_EQ(t.row_start_ns(-5), kT0);  // clamped to the image
  EXPECT_EQ(t.row_start_ns(900), kT0 + 24'000'000);
  // Global shutter: every row at once.
  EXPECT_EQ(shutter_timing(metadata(0, 8'000'000), 480, 1).row_start_ns(479), kT0);
}

TEST(ShutterTiming, MissingOrImpossibleExposureFallsBackAndSaysSo) {
  const ShutterTiming missing = shutter_timing(metadata(0, 0), 480, 10'000'000);
  EXPECT_TRUE(missing.fallback_exposure);
  EXPECT_EQ(missing.exposure_ns, 10'000'000);
  EXPECT_TRUE(shutter_timing(metadata(0, -4), 480, 10'000'000).fallback_exposure);
  // Longer than the frame: impossible, so the default stands in; a default longer than the frame
  // interval is capped at it.
  const ShutterTiming too_long = shutter_timing(metadata(0, 40'000'000), 480, 50'000'000);
  EXPECT_TRUE(too_long.fallback_exposure);
  EXPECT_EQ(too_long.exposure_ns, kFrameNs);
  // Without a known interval the default is taken as it is.
  FrameMetadata no_interval = metadata(0, 0);
  no_interval.frame_duration_ns = 0;
  EXPECT_EQ(shutter_timing(no_interval, 480, 50'000'000).exposure_ns, 50'000'000);
  // A negative readout means a global shutter.
  EXPECT_EQ(shutter_timing(metadata(0, 1'000'000, -5), 480, 1).readout_ns, 0);
}

TEST(PoseTrack, KeepsOrderBoundsAndGaps) {
  PoseTrack track(4, 80'000'000);
  for (uint64_t f = 0; f < 6; ++f) track.add(f, {kT0 + int64_t(f) * kFrameNs, SE3()});
  EXPECT_EQ(track.size(), 4u);
  EXPECT_FALSE(track.contains(1));
  ASSERT_NE(track.previous(3), nullptr);
  EXPECT_EQ(track.previous(3)->time_ns, kT0 + 2 * kFrameNs);
  EXPECT_EQ(track.previous(2), nullptr);  // frame 1 has gone
  ASSERT_NE(track.next(4), nullptr);
  EXPECT_EQ(track.next(4)->time_ns, kT0 + 5 * kFrameNs);
  EXPECT_EQ(track.next(5), nullptr);
  // A lost frame 6 and a tracked frame 7: 2 intervals (67 ms) bridge within 80 ms; 8 and 9 lost
  // too, frame 10 is 100 ms after 7 and stands alone.
  track.add(7, {kT0 + 7 * kFrameNs, SE3()});
  EXPECT_EQ(track.previous(7)->time_ns, kT0 + 5 * kFrameNs);
  track.add(10, {kT0 + 10 * kFrameNs, SE3()});
  EXPECT_EQ(track.previous(10), nullptr);
  EXPECT_EQ(track.next(7), nullptr);
  // Out of order (a look-ahead frame came first) is fine; the same frame again replaces it.
  track.add(9, {kT0 + 9 * kFrameNs, SE3()});
  track.add(9, {kT0 + 9 * kFrameNs, SE3()});
  ASSERT_NE(track.previous(10), nullptr);
  EXPECT_EQ(track.previous(10)->time_ns, kT0 + 9 * kFrameNs);
  EXPECT_EQ(track.next(9)->time_ns, kT0 + 10 * kFrameNs);
  // A restarted stream (frame numbers from 0 again, later times) drops the other run.
  track.add(0, {kT0 + 20 * kFrameNs, SE3()});
  EXPECT_EQ(track.size(), 1u);
}

TEST(ShutterMotion, ConstantVelocityIsExactWithEitherLatency) {
  const SteadyCamera camera;
  for (const int64_t readout : {int64_t(0), int64_t(20'000'000)}) {
    const ShutterTiming timing = shutter_timing(metadata(1, 8'000'000, readout), 480, 1);
    const auto pose_at = [&](uint64_t frame) {
      const int64_t t = shutter_timing(metadata(frame, 8'000'000, readout), 480, 1).mid_ns();
      return TimedPose{t, camera.T_cam_world(t)};
    };
    const TimedPose previous = pose_at(0), current = pose_at(1), next = pose_at(2);
    const ShutterMotion latency0 = estimate_shutter_motion(timing, current, &previous, nullptr);
    const ShutterMotion latency1 = estimate_shutter_motion(timing, current, &previous, &next);
    const ShutterMotion only_next = estimate_shutter_motion(timing, current, nullptr, &next);
    EXPECT_EQ(latency0.state, MotionState::Extrapolated);
    EXPECT_EQ(latency1.state, MotionState::Interpolated);
    EXPECT_EQ(only_next.state, MotionState::Extrapolated);
    for (const ShutterMotion* m : {&latency0, &latency1, &only_next}) {
      // Exact maths: rounding only (1e-15 rad, 1e-15 m scaled by s ~ 1 and the 1 ns clock: 2 rad/s
      // x 0.5 ns = 1e-9 rad of timestamp rounding in row times).
      EXPECT_LT(angle_between(m->T_cam_world_start, camera.T_cam_world(timing.exposure_start_ns)), 1e-12);
      EXPECT_LT(angle_between(m->T_cam_world_end, camera.T_cam_world(timing.end_ns())), 1e-12);
      EXPECT_LT(centre_distance(m->T_cam_world_end, camera.T_cam_world(timing.end_ns())), 1e-12);
      EXPECT_LT(angle_between(m->T_cam_world_mid, current.T_cam_world), 1e-15);
      for (const double row : {0.0, 100.5, 479.0}) {
        const int64_t t = timing.row_mid_ns(row);
        EXPECT_LT(angle_between(m->T_cam_world_at_row(row), camera.T_cam_world(t)), 1e-12) << row;
        EXPECT_LT(centre_distance(m->T_cam_world_at_row(row), camera.T_cam_world(t)), 1e-12) << row;
      }
    }
  }
}

TEST(ShutterMotion, PiecewiseMotionPassesThroughItsThreePoses) {
  // An accelerating camera: latency 1 bends at the frame's pose, and T_cam_world_at follows both halves.
  const ShutterTiming timing = shutter_timing(metadata(1, 8'000'000), 480, 1);
  const TimedPose previous{timing.mid_ns() - kFrameNs, SE3::from_rt({0, 0, 0}, {0, 0, 0.5})};
  const TimedPose current{timing.mid_ns(), SE3::from_rt({0, 0.05, 0}, {0.01, 0, 0.5})};
  const TimedPose next{timing.mid_ns() + kFrameNs, SE3::from_rt({0, 0.2, 0}, {0.05, 0, 0.5})};
  const ShutterMotion m = estimate_shutter_motion(timing, current, &previous, &next);
  EXPECT_LT(angle_between(m.T_cam_world_at(timing.exposure_start_ns), m.T_cam_world_start), 1e-15);
  EXPECT_LT(angle_between(m.T_cam_world_at(timing.mid_ns()), m.T_cam_world_mid), 1e-15);
  EXPECT_LT(angle_between(m.T_cam_world_at(timing.end_ns()), m.T_cam_world_end), 1e-15);
  // The start lies 4 ms back on the previous-current segment, the end 4 ms on current-next.
  EXPECT_NEAR(angle_between(m.T_cam_world_start, current.T_cam_world), 0.05 * 4e6 / kFrameNs, 1e-12);
  EXPECT_NEAR(angle_between(m.T_cam_world_end, current.T_cam_world), 0.15 * 4e6 / kFrameNs, 1e-12);
}

TEST(ShutterMotion, NoNeighbourMeansNoMotion) {
  const ShutterTiming timing = shutter_timing(metadata(1, 8'000'000), 480, 1);
  const ShutterMotion m = estimate_shutter_motion(timing, {timing.mid_ns(), SE3()}, nullptr, nullptr);
  EXPECT_EQ(m.state, MotionState::None);
  EXPECT_EQ(m.why_none, "no neighbouring pose");
  EXPECT_FALSE(m.valid());
}

TEST(ImageMotion, MatchesTheClosedFormOfATurnAndIsZeroWithoutMotion) {
  // A pinhole camera turning at w about its y axis: a point on the optical axis at mid-exposure
  // crosses from -wE/2 to +wE/2, so its image moves f (tan(wE/2) + tan(wE/2)) pixels.
  const CameraModel camera = CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480);
  const SteadyCamera turning{2.0, 0.0};
  const ShutterTiming timing = shutter_timing(metadata(1, 8'000'000), 480, 1);
  const TimedPose previous{timing.mid_ns() - kFrameNs, turning.T_cam_world(timing.mid_ns() - kFrameNs)};
  const TimedPose current{timing.mid_ns(), turning.T_cam_world(timing.mid_ns())};
  const ShutterMotion m = estimate_shutter_motion(timing, current, &previous, nullptr);
  const Vec3 on_axis = current.T_cam_world.inverse() * Vec3{0, 0, 0.5};
  const double expected = 2 * 500 * std::tan(2.0 * 0.008 / 2);
  // The path is followed in 8 straight pieces of a curve that bends by 1e-4 of its length: 1e-6 px.
  EXPECT_NEAR(max_image_motion_px(m, camera, {on_axis}), expected, 1e-4);
  EXPECT_NEAR(expected, 8.0, 0.01);  // 2 rad/s x 8 ms x 500 px
  // A point behind the camera counts for nothing; no motion gives zero.
  EXPECT_EQ(max_image_motion_px(m, camera, {current.T_cam_world.inverse() * Vec3{0, 0, -1}}), 0.0);
  const ShutterMotion still = estimate_shutter_motion(timing, current, &current, nullptr);
  EXPECT_EQ(still.state, MotionState::None);  // the same instant gives no velocity
  const TimedPose same_place{previous.time_ns, current.T_cam_world};
  EXPECT_EQ(max_image_motion_px(estimate_shutter_motion(timing, current, &same_place, nullptr), camera, {on_axis}), 0.0);
}

TEST(ImageMotion, RollingShutterUsesTheRowsOwnWindow) {
  // With a 20 ms readout and a 2 ms exposure, a point's blur is its motion over 2 ms, not 22 ms.
  const CameraModel camera = CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480);
  const SteadyCamera turning{2.0, 0.0};
  const ShutterTiming timing = shutter_timing(metadata(1, 2'000'000, 20'000'000), 480, 1);
  const TimedPose previous{timing.mid_ns() - kFrameNs, turning.T_cam_world(timing.mid_ns() - kFrameNs)};
  const TimedPose current{timing.mid_ns(), turning.T_cam_world(timing.mid_ns())};
  const ShutterMotion m = estimate_shutter_motion(timing, current, &previous, nullptr);
  const Vec3 on_axis = current.T_cam_world.inverse() * Vec3{0, 0, 0.5};
  EXPECT_NEAR(max_image_motion_px(m, camera, {on_axis}), 2 * 500 * std::tan(2.0 * 0.002 / 2), 1e-3);
}

// ---- The stage -----------------------------------------------------------------------------------

FrameContext tracked_frame(uint64_t frame, const SteadyCamera& camera, int64_t exposure_ns,
                           const std::shared_ptr<const CameraModel>& model) {
  FrameContext ctx;
  ctx.input_index = frame;
  ctx.camera.meta = metadata(frame, exposure_ns);
  ctx.camera.height = model->height();
  ctx.camera.width = model->width();
  ctx.camera_model = model;
  ctx.pose.state = TrackState::Tracking;
  // Where the stage puts the pose: the middle of the exposure it assumes (the configured default
  // when the metadata has none).
  ctx.pose.T_cam_world = camera.T_cam_world(shutter_timing(ctx.camera.meta, model->height(), 10'000'000).mid_ns());
  return ctx;
}

// The truth the estimate should reach: the anchor corners' image paths under the analytic motion,
// followed in 1000 steps.
double true_image_motion_px(const SteadyCamera& camera, const CameraModel& model, const ShutterTiming& timing) {
  double longest = 0;
  for (const Vec3& corner : {Vec3{-0.05, -0.05, 0}, Vec3{0.05, -0.05, 0}, Vec3{0.05, 0.05, 0}, Vec3{-0.05, 0.05, 0}}) {
    double length = 0;
    Vec2 previous = *model.project(camera.T_cam_world(timing.exposure_start_ns) * corner);
    for (int i = 1; i <= 1000; ++i) {
      const Vec2 here =
          *model.project(camera.T_cam_world(timing.exposure_start_ns + timing.exposure_ns * i / 1000) * corner);
      length += norm(here - previous);
      previous = here;
    }
    longest = std::max(longest, length);
  }
  return longest;
}

TEST(MotionStage, LatencyZeroExtrapolatesAndSaysWhyWhenItCannot) {
  const auto model = std::make_shared<CameraModel>(CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480));
  const SteadyCamera camera;
  MotionStage stage;
  stage.configure(Config{});
  EXPECT_EQ(stage.latency_frames(), 0);

  FrameContext first = tracked_frame(0, camera, 8'000'000, model);
  stage.process(first);
  EXPECT_EQ(first.motion.state, MotionState::None);
  ASSERT_EQ(first.timings.size(), 1u);
  EXPECT_EQ(first.timings[0].stage, "motion");
  EXPECT_EQ(first.timings[0].skipped, "no neighbouring pose");

  FrameContext second = tracked_frame(1, camera, 0, model);  // no exposure in the metadata
  stage.process(second);
  EXPECT_EQ(second.motion.state, MotionState::Extrapolated);
  EXPECT_TRUE(second.motion.fallback_exposure);
  EXPECT_EQ(second.motion.timing.exposure_ns, Config{}.motion.default_exposure_ns);
  EXPECT_TRUE(second.timings[0].skipped.empty());
  // The pose belongs to the middle of the exposure the frame really had; the stage's timing uses
  // the default 10 ms, so the end is 5 ms after the pose on the constant-velocity path.
  const int64_t end = second.motion.timing.end_ns();
  EXPECT_LT(angle_between(second.motion.T_cam_world_end, camera.T_cam_world(end)), 1e-12);
  // The anchor's corners sit 0.5 m in front, turning at 2 rad/s and moving 0.3 m/s for 10 ms:
  // 7-10 px. 8 straight pieces of paths that bend little: well within 0.01 px.
  const double truth = true_image_motion_px(camera, *model, second.motion.timing);
  EXPECT_GT(truth, 5.0);
  EXPECT_NEAR(second.motion.max_image_motion_px, truth, 0.01);

  FrameContext lost;
  lost.input_index = 2;
  lost.camera.meta = metadata(2, 8'000'000);
  lost.camera_model = model;
  lost.pose.state = TrackState::Lost;
  stage.process(lost);
  EXPECT_EQ(lost.motion.state, MotionState::None);
  EXPECT_EQ(lost.motion.why_none, "no pose: tracking lost");
  EXPECT_EQ(lost.timings[0].skipped, "no pose: tracking lost");

  // Frame 3 bridges the lost frame with frame 1 (two intervals back).
  FrameContext after = tracked_frame(3, camera, 8'000'000, model);
  stage.process(after);
  EXPECT_EQ(after.motion.state, MotionState::Extrapolated);
  EXPECT_LT(angle_between(after.motion.T_cam_world_start, camera.T_cam_world(after.motion.timing.exposure_start_ns)),
            1e-12);
}

TEST(MotionStage, APredictedPoseGetsMotionButStaysOutOfTheTrack) {
  // The tracker's prediction lies on the constant-velocity path of the last measurements, so the
  // motion over its exposure follows that path; the next measured frame must still interpolate
  // between measurements only.
  const auto model = std::make_shared<CameraModel>(CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480));
  const SteadyCamera camera;
  MotionStage stage;
  stage.configure(Config{});
  for (uint64_t frame : {0u, 1u}) {
    FrameContext ctx = tracked_frame(frame, camera, 8'000'000, model);
    stage.process(ctx);
  }
  FrameContext predicted = tracked_frame(2, camera, 8'000'000, model);
  predicted.pose.state = TrackState::Predicted;
  stage.process(predicted);
  ASSERT_EQ(predicted.motion.state, MotionState::Extrapolated);
  // SteadyCamera moves at constant velocity: exact to rounding.
  EXPECT_LT(angle_between(predicted.motion.T_cam_world_start, camera.T_cam_world(predicted.motion.timing.exposure_start_ns)),
            1e-9);
  EXPECT_LT(angle_between(predicted.motion.T_cam_world_end, camera.T_cam_world(predicted.motion.timing.end_ns())), 1e-9);
  EXPECT_GT(predicted.motion.max_image_motion_px, 5.0);

  // Frame 3 is measured: its previous neighbour is frame 1, the last measurement, not the prediction.
  FrameContext after = tracked_frame(3, camera, 8'000'000, model);
  after.pose.T_cam_world = SE3(rotation_from_vector({0, 0.01, 0}), {0, 0, 0}) * after.pose.T_cam_world;
  stage.process(after);
  ASSERT_EQ(after.motion.state, MotionState::Extrapolated);
  FrameContext again = tracked_frame(4, camera, 8'000'000, model);
  stage.process(again);
  EXPECT_EQ(again.motion.state, MotionState::Extrapolated);
}

TEST(MotionStage, LatencyOneInterpolatesWhenShownTheNextFrame) {
  const auto model = std::make_shared<CameraModel>(CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480));
  const SteadyCamera camera;
  Config config;
  config.motion.latency_frames = 1;
  MotionStage stage;
  stage.configure(config);
  EXPECT_EQ(stage.latency_frames(), 1);
  std::vector<FrameContext> frames;
  for (uint64_t f = 0; f < 4; ++f) frames.push_back(tracked_frame(f, camera, 8'000'000, model));
  // What a runner that holds one frame back does: track n+1, show it, then process n.
  stage.look_ahead(frames[0]);
  for (size_t n = 0; n < 3; ++n) {
    stage.look_ahead(frames[n + 1]);
    stage.process(frames[n]);
  }
  EXPECT_EQ(frames[0].motion.state, MotionState::Extrapolated);  // no previous: backwards from 0-1
  EXPECT_EQ(frames[1].motion.state, MotionState::Interpolated);
  EXPECT_EQ(frames[2].motion.state, MotionState::Interpolated);
  for (size_t n = 0; n < 3; ++n) {
    EXPECT_LT(angle_between(frames[n].motion.T_cam_world_end, camera.T_cam_world(frames[n].motion.timing.end_ns())),
              1e-12);
  }
  // Without the look-ahead (today's runner) the last frame is extrapolated.
  stage.process(frames[3]);
  EXPECT_EQ(frames[3].motion.state, MotionState::Extrapolated);
}

TEST(MotionStage, DisabledOrUnconfiguredSkipsWithTheReason) {
  FrameContext ctx;
  ctx.pose.state = TrackState::Tracking;
  MotionStage unconfigured;
  unconfigured.process(ctx);
  EXPECT_EQ(ctx.timings.back().skipped, "not configured");
  Config config;
  config.motion.enabled = false;
  MotionStage disabled;
  disabled.configure(config);
  disabled.process(ctx);
  EXPECT_EQ(ctx.timings.back().skipped, "disabled");
  EXPECT_EQ(ctx.motion.state, MotionState::None);
  config.motion.enabled = true;
  config.track.enabled = false;
  MotionStage no_tracking;
  no_tracking.configure(config);
  no_tracking.process(ctx);
  EXPECT_EQ(ctx.timings.back().skipped, "tracking disabled");
}

TEST(MotionStage, RefusesImpossibleValuesFromCode) {
  Config config;
  config.file = "code.toml";
  config.motion.latency_frames = 2;
  MotionStage stage;
  try {
    stage.configure(config);
    ADD_FAILURE() << "latency_frames = 2 was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("code.toml: motion.latency_frames: expected 0 or 1, got 2"), std::string::npos)
        << e.what();
  }
  config.motion.latency_frames = 0;
  config.motion.default_exposure_ns = 0;
  EXPECT_THROW(stage.configure(config), ConfigError);
}

TEST(MotionStage, PoseTimeIsTheTagRowsMidExposure) {
  const ShutterTiming global = shutter_timing(metadata(0, 8'000'000), 480, 1);
  const ShutterTiming rolling = shutter_timing(metadata(0, 2'000'000, 24'000'000), 481, 1);
  PoseEstimate pose;
  TagObservation tag;
  tag.id = 0;
  tag.corners = {Vec2{10, 100}, Vec2{50, 100}, Vec2{50, 60}, Vec2{10, 60}};  // mean row 80
  pose.tags.push_back(tag);
  TagObservation stranger = tag;
  stranger.id = 7;  // not in the bundle: ignored
  stranger.corners = {Vec2{0, 470}, Vec2{1, 470}, Vec2{1, 471}, Vec2{0, 471}};
  pose.tags.push_back(stranger);
  const std::vector<BundleTag> bundle{BundleTag{}};
  EXPECT_EQ(tracked_pose_time_ns(global, pose, bundle), global.mid_ns());
  EXPECT_EQ(tracked_pose_time_ns(rolling, pose, bundle), kT0 + 80 * 50'000 + 1'000'000);
  EXPECT_EQ(tracked_pose_time_ns(rolling, PoseEstimate{}, bundle), rolling.mid_ns());
}

}  // namespace
}  // namespace arpipe
