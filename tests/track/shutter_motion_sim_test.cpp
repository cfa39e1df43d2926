// The motion stage against the simulator's ground truth: exposure-start and exposure-end poses on
// tag-pan (tracked through motion blur, latency 0 and 1), the interpolation model alone on the
// truth of tag-pan and of the default capture, and the time a tracked pose belongs to under a
// rolling shutter. Set ARPIPE_MOTION_TAG_PAN=<recording dir> to measure on a full-quality capture
// (docs/ARCHITECTURE.md "The motion stage" gives the command and the numbers).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "capture/recording/recording_reader.h"
#include "capture/sim/camera_trajectory.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "core/motion/motion_stage.h"
#include "core/track/tag_tracker.h"
#include "tests/track/tracked_capture.h"
#include "tests/track/tracking_config.h"
#include "tests/track/simulated_capture.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using test::angle_deg;
using test::centre_mm;

using test::SimulatedCapture;

struct Summary {
  std::vector<double> values;
  void add(double v) { values.push_back(v); }
  double median() const {
    std::vector<double> v = values;
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
  }
  double max() const { return values.empty() ? 0 : *std::max_element(values.begin(), values.end()); }
  std::string text(const char* unit) const { return fmt::format("median {:.3f} {}, max {:.3f} {}", median(), unit, max(), unit); }
};

struct WindowErrors {
  Summary start_deg, start_mm, end_deg, end_mm;
  int frames = 0;
  void add(const ShutterMotion& m, const GroundTruthFrame& truth) {
    start_deg.add(angle_deg(m.T_cam_world_start, truth.T_cam_world_start));
    start_mm.add(centre_mm(m.T_cam_world_start, truth.T_cam_world_start));
    end_deg.add(angle_deg(m.T_cam_world_end, truth.T_cam_world_end));
    end_mm.add(centre_mm(m.T_cam_world_end, truth.T_cam_world_end));
    ++frames;
  }
  void print(const std::string& label) const {
    fmt::print("{} ({} frames): start {} / {}; end {} / {}\n", label, frames, start_deg.text("deg"), start_mm.text("mm"),
               end_deg.text("deg"), end_mm.text("mm"));
  }
};

// The interpolation model alone: the truth's mid-exposure poses stand in for tracked poses.
WindowErrors model_errors(const RecordingReader& reader, int latency, PoseInterpolation method) {
  const auto& truth = reader.ground_truth();
  const int rows = reader.camera_model().height();
  WindowErrors errors;
  for (size_t i = 1; i + 1 < truth.size(); ++i) {
    const auto timed = [&](size_t k) {
      return TimedPose{reader.metadata(k).exposure_mid_ns(), truth[k].T_cam_world_mid};
    };
    const TimedPose previous = timed(i - 1), current = timed(i), next = timed(i + 1);
    const ShutterTiming timing = shutter_timing(reader.metadata(i), rows, 1);
    errors.add(estimate_shutter_motion(timing, current, &previous, latency == 1 ? &next : nullptr, method), truth[i]);
  }
  return errors;
}

// The default capture: a camera orbiting at 0.45-0.55 m (its centre moves while it turns).
const fs::path kDefaultCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";

TEST(ShutterMotionModel, CentreLineMatchesTheTruthAtLeastAsWellAsTheScrew) {
  ASSERT_TRUE(fs::exists(kDefaultCapture / "recording.json")) << "the build simulates " << kDefaultCapture;
  const RecordingReader reader(kDefaultCapture);
  for (const int latency : {0, 1}) {
    const WindowErrors line = model_errors(reader, latency, PoseInterpolation::CentreLine);
    const WindowErrors screw = model_errors(reader, latency, PoseInterpolation::Screw);
    line.print(fmt::format("default-capture truth, latency {}, centre line", latency));
    screw.print(fmt::format("default-capture truth, latency {}, screw", latency));
    // The rotations are the same slerp in both models; only the centre's path differs. On this
    // orbit about the tag (itself screw-like) the screw is nearer by 0.005 mm in the median
    // (measured 0.020 vs 0.015 mm; max 0.165 mm both): at 30 fps the choice is second order and
    // a hundred times below the tracker's noise, so the straight centre line of a hand-held
    // camera stays the default. Both are far below a millimetre and a tenth of a degree.
    for (const WindowErrors* e : {&line, &screw}) {
      EXPECT_LT(e->start_mm.max(), 0.2);
      EXPECT_LT(e->end_mm.max(), 0.2);
      EXPECT_LT(e->start_deg.max(), 0.03);
      EXPECT_LT(e->end_deg.max(), 0.03);
    }
    EXPECT_LT(std::abs(line.end_mm.median() - screw.end_mm.median()), 0.01);
    EXPECT_NEAR(line.end_deg.max(), screw.end_deg.max(), 1e-9);
  }
}

// tag-pan through the tracker and the stage. Each frame's tracked pose and the motion stage at
// latency 0 (in stream order) and latency 1 (shown the next tracked frame first).
struct TagPanRun {
  WindowErrors latency0, latency1, model0, model1;
  int frames_beyond_bound = 0;  // start or end error above the per-frame bound (see the test)
  std::string worst_bound;
  Summary pose_deg, pose_mm;  // the tracker's own error at mid-exposure: the floor of the above
  int frames = 0, tracked = 0;
};

TagPanRun run_tag_pan(const fs::path& dir) {
  const RecordingReader reader(dir);
  const auto& truth = reader.ground_truth();
  Config config = test::tracking_config();  // the default bundle: tag 0 of tag36h11, 10 cm, at the origin, as simulated
  std::vector<FrameContext> frames = test::tracked_capture(reader, config);
  TagPanRun run;
  run.frames = int(frames.size());
  MotionStage stage0, stage1;
  stage0.configure(config);
  config.motion.latency_frames = 1;
  stage1.configure(config);
  std::vector<FrameContext> held = frames;  // latency 1 writes its own copy
  stage1.look_ahead(held[0]);
  for (size_t i = 0; i < frames.size(); ++i) {
    stage0.process(frames[i]);
    if (i + 1 < held.size()) stage1.look_ahead(held[i + 1]);
    stage1.process(held[i]);
    if (frames[i].pose.state != TrackState::Tracking) continue;
    ++run.tracked;
    run.pose_deg.add(angle_deg(frames[i].pose.T_cam_world, truth[i].T_cam_world_mid));
    run.pose_mm.add(centre_mm(frames[i].pose.T_cam_world, truth[i].T_cam_world_mid));
    if (frames[i].motion.valid()) run.latency0.add(frames[i].motion, truth[i]);
    if (held[i].motion.state == MotionState::Interpolated) run.latency1.add(held[i].motion, truth[i]);
  }
  // Per frame: start and end are sums of tracked poses with weights whose magnitudes add up to at
  // most 1.24 (the end 4 ms past the pose, extrapolated over a 33 ms interval: 1.12 + 0.12), so
  // each error stays within 1.25x the largest tracked-pose error of the frames around it, plus
  // the model's own error there (the same interpolation of the true poses), plus rounding room
  // (0.1 mm, 0.01 deg).
  const int64_t n = int64_t(frames.size());
  const auto pose_error = [&](int64_t k, bool degrees) {
    const SE3& tracked = frames[size_t(k)].pose.T_cam_world;
    return degrees ? angle_deg(tracked, truth[size_t(k)].T_cam_world_mid) : centre_mm(tracked, truth[size_t(k)].T_cam_world_mid);
  };
  for (const int latency : {0, 1}) {
    const std::vector<FrameContext>& out = latency == 0 ? frames : held;
    for (int64_t i = 1; i + 1 < n; ++i) {
      const ShutterMotion& m = out[size_t(i)].motion;
      // A predicted frame's motion follows the prediction, whose error is the tracker's own
      // (tests/track/tag_tracker_prediction_test.cpp); this bound is about measured poses.
      if (!m.valid() || out[size_t(i)].pose.state != TrackState::Tracking) continue;
      double worst_deg = 0, worst_mm = 0;
      for (int64_t k = std::max<int64_t>(i - 2, 0); k <= std::min(i + 2, n - 1); ++k) {
        if (frames[size_t(k)].pose.state != TrackState::Tracking) continue;
        worst_deg = std::max(worst_deg, pose_error(k, true));
        worst_mm = std::max(worst_mm, pose_error(k, false));
      }
      const auto timed = [&](int64_t k) { return TimedPose{reader.metadata(size_t(k)).exposure_mid_ns(), truth[size_t(k)].T_cam_world_mid}; };
      const TimedPose p = timed(i - 1), c = timed(i), x = timed(i + 1);
      const ShutterMotion model = estimate_shutter_motion(m.timing, c, &p, latency == 1 ? &x : nullptr);
      const GroundTruthFrame& t = truth[size_t(i)];
      const double bound_start_deg = 1.25 * worst_deg + angle_deg(model.T_cam_world_start, t.T_cam_world_start) + 0.01;
      const double bound_end_deg = 1.25 * worst_deg + angle_deg(model.T_cam_world_end, t.T_cam_world_end) + 0.01;
      const double bound_mm = 1.25 * worst_mm + 0.1;
      const double start_deg = angle_deg(m.T_cam_world_start, t.T_cam_world_start);
      const double end_deg = angle_deg(m.T_cam_world_end, t.T_cam_world_end);
      const double start_mm = centre_mm(m.T_cam_world_start, t.T_cam_world_start);
      const double end_mm = centre_mm(m.T_cam_world_end, t.T_cam_world_end);
      if (start_deg > bound_start_deg || end_deg > bound_end_deg || start_mm > bound_mm || end_mm > bound_mm) {
        ++run.frames_beyond_bound;
        run.worst_bound += fmt::format("latency {} frame {}: start {:.3f} deg {:.2f} mm, end {:.3f} deg {:.2f} mm; "
                                       "bounds {:.3f} / {:.3f} deg, {:.2f} mm\n",
                                       latency, i, start_deg, start_mm, end_deg, end_mm, bound_start_deg, bound_end_deg,
                                       bound_mm);
      }
    }
  }
  run.model0 = model_errors(reader, 0, PoseInterpolation::CentreLine);
  run.model1 = model_errors(reader, 1, PoseInterpolation::CentreLine);
  return run;
}

// When the tracked pose was true: for each tracked frame, the instant (searched in 0.1 ms steps
// over the frame's window, widened by a frame each side) whose true pose puts the anchor's centre
// nearest to where the tracked pose puts it,
// as an offset from the time the stage gives the pose (tracked_pose_time_ns) and from the middle
// row's mid-exposure.
struct PoseTimeOffsets {
  Summary from_stage_ms, from_middle_row_ms;
};

PoseTimeOffsets pose_time_offsets(const fs::path& dir) {
  const RecordingReader reader(dir);
  const sim::SimScene scene = sim::load_sim_scene(dir / sim::kSceneCopyFile);
  const auto camera = std::make_shared<CameraModel>(reader.camera_model());
  int64_t longest = 0;
  for (size_t i = 0; i < reader.frame_count(); ++i) longest = std::max(longest, reader.metadata(i).exposure_ns);
  const double duration_s = double(reader.frame_count()) / scene.camera.fps + double(longest + scene.camera.readout_ns) * 1e-9;
  const sim::CameraTrajectory trajectory(scene.trajectory, scene.camera, duration_s, scene.render.seed);
  const auto truth_at = [&](int64_t t_ns) {
    return trajectory.T_cam_world(double(t_ns - scene.camera.first_exposure_start_ns) * 1e-9);
  };
  Config config = test::tracking_config();
  TagTracker tracker;
  tracker.configure(config);
  PoseTimeOffsets offsets;
  for (size_t i = 0; i < reader.frame_count(); ++i) {
    FrameContext ctx;
    reader.read(i, ctx.camera);
    ctx.camera_model = camera;
    ctx.input_index = i;
    tracker.process(ctx);
    if (ctx.pose.state != TrackState::Tracking) continue;
    const ShutterTiming timing = shutter_timing(ctx.camera.meta, camera->height(), 1);
    const int64_t frame = ctx.camera.meta.frame_duration_ns;
    // Only where the camera moves enough for the time to matter (0.05 deg over the window).
    if (angle_deg(truth_at(timing.exposure_start_ns), truth_at(timing.end_ns())) < 0.05) continue;
    int64_t best = timing.mid_ns();
    double best_error = 1e9;
    // Distance in the image of the anchor's centre: where the virtual layer lands. (The rotation
    // alone would mix in the roll that PnP makes of a rolling shutter's skew.)
    const Vec2 tracked_centre = *camera->project(ctx.pose.T_cam_world * Vec3{0, 0, 0});
    for (int64_t t = timing.exposure_start_ns - frame; t <= timing.end_ns() + frame; t += 100'000) {
      const auto at_t = camera->project(truth_at(t) * Vec3{0, 0, 0});
      if (!at_t) continue;
      const double error = norm(*at_t - tracked_centre);
      if (error < best_error) {
        best_error = error;
        best = t;
      }
    }
    offsets.from_stage_ms.add(double(best - tracked_pose_time_ns(timing, ctx.pose, config.track.bundle)) * 1e-6);
    offsets.from_middle_row_ms.add(double(best - timing.mid_ns()) * 1e-6);
  }
  return offsets;
}

TEST(ShutterMotionSim, RollingShutterPoseBelongsToTheTagRowsMidExposure) {
  // The first 12 frames of rolling-shutter (25 ms readout, 2 ms exposure, a pan at ~1000 px/s)
  // at 1 sample per pixel, or a given capture (ARPIPE_MOTION_POSE_TIME=<recording dir>).
  std::optional<SimulatedCapture> simulated;
  fs::path dir;
  if (const char* given = std::getenv("ARPIPE_MOTION_POSE_TIME")) {
    dir = given;
  } else {
    simulated.emplace("rolling-shutter.toml", 1, 12);
    dir = simulated->dir();
  }
  const PoseTimeOffsets offsets = pose_time_offsets(dir);
  const auto abs_summary = [](const Summary& s) {
    Summary a;
    for (double v : s.values) a.add(std::abs(v));
    return a;
  };
  fmt::print("{} frames; best time - stage's pose time: {}; |.|: {}\n", offsets.from_stage_ms.values.size(),
             offsets.from_stage_ms.text("ms"), abs_summary(offsets.from_stage_ms).text("ms"));
  fmt::print("best time - middle row's mid-exposure: {}; |.|: {}\n", offsets.from_middle_row_ms.text("ms"),
             abs_summary(offsets.from_middle_row_ms).text("ms"));
  ASSERT_GE(offsets.from_stage_ms.values.size(), 8u);
  // Measured on the full 36 frames at 9 samples: 0.2 ms (median |offset|) from the tag rows'
  // mid-exposure, 2.6 ms (up to 8.6 ms) from the middle row's. 1 ms is half the exposure and
  // 1 px of image motion at this pan speed.
  EXPECT_LT(abs_summary(offsets.from_stage_ms).median(), 1.0);
  EXPECT_LT(abs_summary(offsets.from_stage_ms).median(), abs_summary(offsets.from_middle_row_ms).median());
}

void print(const TagPanRun& run) {
  fmt::print("tag-pan: {} of {} frames tracked; tracker pose at mid-exposure: {} / {}\n", run.tracked, run.frames,
             run.pose_deg.text("deg"), run.pose_mm.text("mm"));
  run.latency0.print("tag-pan tracked, latency 0");
  run.latency1.print("tag-pan tracked, latency 1");
  run.model0.print("tag-pan truth poses, latency 0");
  run.model1.print("tag-pan truth poses, latency 1");
}

TEST(ShutterMotionSim, TagPanStartAndEndPosesMatchTheTruth) {
  // By default a 1-sample-per-pixel tag-pan (the full 16 samples take a minute to render): each
  // pixel sees one instant of its exposure, so the blur is dithered and the tracker a little
  // noisier than on the real capture.
  std::optional<SimulatedCapture> simulated;
  fs::path dir;
  if (const char* given = std::getenv("ARPIPE_MOTION_TAG_PAN")) {
    dir = given;
  } else {
    simulated.emplace("tag-pan.toml", 1);
    dir = simulated->dir();
  }
  const TagPanRun run = run_tag_pan(dir);
  print(run);
  // The tag stays in view throughout; the fastest sweeps (20-30 px of blur) cost up to 8 frames
  // (measured: 40 of 48 at 1 sample per pixel, 41 at 16).
  EXPECT_GE(run.tracked, run.frames - 10);
  ASSERT_GE(run.latency0.frames, run.tracked - 4);  // a frame whose predecessor was lost has no velocity
  ASSERT_GE(run.latency1.frames, run.tracked - 8);  // ... nor one whose successor was lost, at latency 1

  // The model alone (the truth's mid poses through the same interpolation; deterministic): the
  // camera turns in place, so the centre is exact; the rotation is off where the pan speeds up or
  // reverses within a frame. Measured: start median 0.054 deg, max 1.69 deg; end median 0.067 /
  // 0.045 deg, max 2.20 / 1.14 deg at latency 0 / 1.
  for (const WindowErrors* e : {&run.model0, &run.model1}) {
    EXPECT_LT(e->start_mm.max(), 1e-6);
    EXPECT_LT(e->end_mm.max(), 1e-6);
    EXPECT_LT(e->start_deg.median(), 0.07);
    EXPECT_LT(e->end_deg.median(), 0.08);
    EXPECT_LT(e->start_deg.max(), 1.8);
  }
  EXPECT_LT(run.model0.end_deg.max(), 2.3);
  EXPECT_LT(run.model1.end_deg.max(), 1.2);  // interpolation halves the worst end error

  // Through the tracker, the tracked poses' own errors dominate: median 0.3-0.7 deg and 3-6 mm at
  // mid-exposure, growing with the blur to 3-5 deg and 30-57 mm on single frames under 20-30 px
  // of blur (the tracker's bias through blur, issue 6's tracking part). Each frame's start and end
  // stay within the bound built in run_tag_pan from its neighbours' tracked-pose errors.
  EXPECT_EQ(run.frames_beyond_bound, 0) << run.worst_bound;
  // And in the large: never far beyond the tracker itself.
  for (const WindowErrors* e : {&run.latency0, &run.latency1}) {
    EXPECT_LT(e->end_deg.median(), 2 * run.pose_deg.median() + 0.1);
    EXPECT_LT(e->end_mm.median(), 2 * run.pose_mm.median() + 0.1);
  }
}

}  // namespace
}  // namespace arpipe
