// Benchmark: tracking run time against pose error, over a capture with ground truth, for the
// detector's quad decimation and the corner refinement (the tracker's quality knobs).
// `arpipe bench pose [--capture DIR]` prints a markdown table for docs/BENCHMARKS.md.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/command_line.h"
#include "bench/benchmarks.h"
#include "capture/recording/recording_reader.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/track/tag_tracker.h"

namespace arpipe {
namespace {

struct Errors {
  std::vector<double> position_mm, rotation_deg, anchor_px, ms;
  int tracked = 0, frames = 0;
  size_t worst_frame = 0;  // of the centre error
};

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double maximum(const std::vector<double>& v) { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); }

Errors measure(const RecordingReader& reader, const std::vector<Frame>& frames, double decimate, bool refine) {
  Config config;
  config.track.quad_decimate = decimate;
  config.track.refine_corners = refine;
  config.render.objects = {SceneObject{}};  // the tracker skips frames with nothing virtual in the scene
  TagTracker tracker;
  tracker.configure(config);
  auto model = std::make_shared<const CameraModel>(reader.camera_model());
  Errors e;
  for (int pass = 0; pass < 3; ++pass)  // the first pass warms caches; timings from all three
    for (size_t i = 0; i < frames.size(); ++i) {
      FrameContext ctx;
      ctx.camera = frames[i];
      ctx.camera_model = model;
      const auto start = std::chrono::steady_clock::now();
      tracker.process(ctx);
      const double ms = milliseconds_since(start);
      if (pass == 0) continue;
      e.ms.push_back(ms);
      if (pass != 1) continue;
      ++e.frames;
      if (ctx.pose.state != TrackState::Tracking) continue;
      ++e.tracked;
      const SE3& truth = reader.ground_truth()[i].T_cam_world_mid;
      const SE3& estimate = ctx.pose.T_cam_world;
      // Camera centre in the world frame, and the relative rotation.
      const Vec3 centre_error = estimate.inverse().translation() - truth.inverse().translation();
      if (e.position_mm.empty() || norm(centre_error) * 1e3 > maximum(e.position_mm)) e.worst_frame = i;
      e.position_mm.push_back(norm(centre_error) * 1e3);
      e.rotation_deg.push_back(rotation_angle_between(estimate, truth) * 180 / M_PI);
      const auto a = model->project(estimate * Vec3{0, 0, 0});
      const auto b = model->project(truth * Vec3{0, 0, 0});
      if (a && b) e.anchor_px.push_back(std::hypot((*a)[0] - (*b)[0], (*a)[1] - (*b)[1]));
    }
  return e;
}

int run_pose_benchmark(const std::string& capture) {
  log::set_max_level(log::Level::Warning);
  try {
    RecordingReader reader(capture);
    if (reader.ground_truth().empty()) {
      log::error("{}: no ground truth", capture);
      return 2;
    }
    std::vector<Frame> frames(reader.frame_count());
    for (size_t i = 0; i < frames.size(); ++i) reader.read(i, frames[i]);
    fmt::print("capture: {} ({} frames, {}x{} {})\n\n", capture, frames.size(), reader.info().width,
               reader.info().height, pixel_format_name(reader.info().pixel_format));
    fmt::print(
        "| quad_decimate | refine_corners | tracked | ms/frame (median) | centre error mm (median / max) | "
        "rotation error deg (median / max) | anchor error px (median / max) | worst frame |\n"
        "|---:|---|---:|---:|---:|---:|---:|---:|\n");
    for (double decimate : {1.0, 2.0, 4.0})
      for (bool refine : {false, true}) {
        const Errors e = measure(reader, frames, decimate, refine);
        fmt::print("| {} | {} | {}/{} | {:.2f} | {:.2f} / {:.2f} | {:.3f} / {:.3f} | {:.3f} / {:.3f} | {} |\n", decimate,
                   refine ? "yes" : "no", e.tracked, e.frames, median(e.ms), median(e.position_mm),
                   maximum(e.position_mm), median(e.rotation_deg), maximum(e.rotation_deg), median(e.anchor_px),
                   maximum(e.anchor_px), e.worst_frame);
      }
    return 0;
  } catch (const std::exception& ex) {
    log::error("{}", ex.what());
    return 2;
  }
}

}  // namespace

void add_pose_benchmark(CLI::App& bench) {
  CLI::App* command = bench.add_subcommand(
      "pose", "tracking time against pose error for the detector's quad decimation and corner refinement");
  auto capture = std::make_shared<std::string>("build/default-capture");
  command->add_option("--capture", *capture, "a recording with ground truth")->type_name("DIR");
  cli::on_run(command, [capture] { return run_pose_benchmark(*capture); }, cli::Failure{});
}

}  // namespace arpipe
