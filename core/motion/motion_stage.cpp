// The motion stage: a PoseTrack of recent tracked frames, and per frame the shutter motion
// estimated from it, with the image motion that tells later stages whether blur is worth drawing.
#include "core/motion/motion_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/log.h"
#include "core/motion/image_motion.h"
#include "core/motion/pose_track.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/track/bundle_tag_geometry.h"

namespace arpipe {

namespace {

// Neighbours further than this many frame intervals away are not used: one dropped or lost frame
// between them is bridged (2 intervals), a longer gap is not.
constexpr double kMaxGapFrames = 2.5;
// When the metadata has no frame interval.
constexpr int64_t kMaxGapWithoutIntervalNs = 100'000'000;

std::string config_source(const Config& config) {
  return config.file.empty() ? std::string("config") : config.file.string();
}

}  // namespace

int64_t tracked_pose_time_ns(const ShutterTiming& timing, const PoseEstimate& pose, const std::vector<BundleTag>& bundle) {
  double row_sum = 0;
  int corners = 0;
  for (const TagObservation& tag : pose.tags) {
    if (std::none_of(bundle.begin(), bundle.end(), [&](const BundleTag& b) { return b.id == tag.id; })) continue;
    for (const Vec2& corner : tag.corners) {
      row_sum += corner[1];
      ++corners;
    }
  }
  if (corners == 0 || timing.readout_ns <= 0) return timing.mid_ns();
  return timing.row_mid_ns(row_sum / corners);
}

struct MotionStage::Impl {
  bool configured = false;
  MotionConfig config;
  bool tracking_on = false;
  std::vector<BundleTag> bundle;
  std::vector<Vec3> reference_points;  // world: the anchor's tag corners and the objects' origins
  PoseTrack track;
  bool warned_exposure_cap = false;

  int rows(const FrameContext& ctx) const {
    return ctx.camera_model ? ctx.camera_model->height() : std::max(ctx.camera.height, 1);
  }
  ShutterTiming timing(const FrameContext& ctx) const {
    return shutter_timing(ctx.camera.meta, rows(ctx), config.default_exposure_ns);
  }
  void observe(const FrameContext& ctx);
  std::string estimate(FrameContext& ctx);  // returns the skip reason, empty when it ran
};

void MotionStage::Impl::observe(const FrameContext& ctx) {
  if (ctx.pose.state != TrackState::Tracking || track.contains(ctx.input_index)) return;
  const ShutterTiming t = timing(ctx);
  const int64_t interval = ctx.camera.meta.frame_duration_ns;
  track.set_max_gap_ns(interval > 0 ? std::llround(kMaxGapFrames * double(interval)) : kMaxGapWithoutIntervalNs);
  track.add(ctx.input_index, {tracked_pose_time_ns(t, ctx.pose, bundle), ctx.pose.T_cam_world});
}

std::string MotionStage::Impl::estimate(FrameContext& ctx) {
  ShutterMotion& motion = ctx.motion;
  if (!configured) return "not configured";
  if (!config.enabled) return "disabled";
  if (!tracking_on) return "tracking disabled";
  if (ctx.pose.state != TrackState::Tracking && ctx.pose.state != TrackState::Predicted) {
    motion.why_none = ctx.pose.state == TrackState::Lost ? "no pose: tracking lost" : "no pose: tracking did not run";
    return std::string(motion.why_none);
  }
  // A predicted pose is the tracker's constant-velocity extrapolation: it has motion (the frames it
  // stands in for are the blurred ones), but it stays out of the track, which holds measurements.
  const bool predicted = ctx.pose.state == TrackState::Predicted;
  if (!predicted) observe(ctx);
  const ShutterTiming t = timing(ctx);
  const TimedPose predicted_pose{tracked_pose_time_ns(t, ctx.pose, bundle), ctx.pose.T_cam_world};
  const TimedPose* current = predicted ? &predicted_pose : track.find(ctx.input_index);
  if (!current) return "no pose";  // not reached: observe() just added it
  if (t.fallback_exposure && ctx.camera.meta.frame_duration_ns > 0 &&
      config.default_exposure_ns > ctx.camera.meta.frame_duration_ns && !warned_exposure_cap) {
    log::warn("motion: motion.default_exposure_ms = {} is longer than the frame interval ({} ms); using the interval",
              double(config.default_exposure_ns) * 1e-6, double(ctx.camera.meta.frame_duration_ns) * 1e-6);
    warned_exposure_cap = true;
  }
  // With latency 1 the runner has shown this stage the next frame already (look_ahead); it has no
  // pose at the end of the stream or when tracking lost it, and the end is then extrapolated.
  const TimedPose* next = config.latency_frames >= 1 ? track.after(ctx.input_index, current->time_ns) : nullptr;
  motion = estimate_shutter_motion(t, *current, track.before(ctx.input_index, current->time_ns), next);
  if (!motion.valid()) return std::string(motion.why_none);
  if (ctx.camera_model) motion.max_image_motion_px = max_image_motion_px(motion, *ctx.camera_model, reference_points);
  return {};
}

MotionStage::MotionStage() : impl_(std::make_unique<Impl>()) {}
MotionStage::~MotionStage() = default;

void MotionStage::configure(const Config& config) {
  const MotionConfig& motion = config.motion;
  const std::string source = config_source(config);
  if (motion.latency_frames != 0 && motion.latency_frames != 1)
    throw ConfigError(fmt::format("{}: motion.latency_frames: expected 0 or 1, got {}", source, motion.latency_frames));
  if (motion.default_exposure_ns <= 0)
    throw ConfigError(fmt::format("{}: motion.default_exposure_ms: expected a number > 0, got {}", source,
                                  double(motion.default_exposure_ns) * 1e-6));
  std::vector<Vec3> points;
  for (const BundleTag& tag : config.track.bundle)
    for (const Vec3& corner : bundle_tag_world_corners(tag)) points.push_back(corner);
  for (const SceneObject& object : config.render.objects) points.push_back(object.position_m);

  impl_->config = motion;
  impl_->tracking_on = config.track.enabled;
  impl_->bundle = config.track.bundle;
  impl_->reference_points = std::move(points);
  impl_->track.clear();  // a new bundle may define another world frame
  impl_->warned_exposure_cap = false;
  impl_->configured = true;
}

int MotionStage::latency_frames() const noexcept { return impl_->configured ? impl_->config.latency_frames : 0; }

void MotionStage::look_ahead(const FrameContext& next) noexcept {
  try {
    if (impl_->configured && impl_->config.enabled && impl_->tracking_on) impl_->observe(next);
  } catch (const std::exception& e) {
    log::debug("motion: frame {}: {}", next.input_index, e.what());
  }
}

void MotionStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  std::string skipped;
  ctx.motion = ShutterMotion{};
  try {
    skipped = impl_->estimate(ctx);
  } catch (const std::exception& e) {
    // Only allocation failures get here; one frame without motion is the right outcome.
    log::debug("motion: frame {}: {}", ctx.input_index, e.what());
    ctx.motion = ShutterMotion{};
    ctx.motion.why_none = "internal error";
    skipped = "internal error";
  }
  const double ms = milliseconds_since(start);
  try {
    ctx.record_timing("motion", ms, std::move(skipped));
  } catch (...) {
    // Out of memory while recording a timing; the motion is still valid.
  }
}

}  // namespace arpipe
