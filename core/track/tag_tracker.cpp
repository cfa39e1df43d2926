// The track stage: AprilTag detection and the camera pose relative to the anchor (a tag or a bundle).
// World frame = anchor: x along the tag's right edge, y along its top edge, z out of its face.
#include "core/track/tag_tracker.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <unordered_map>
#include <vector>

#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/track/bundle_tag_geometry.h"
#include "core/track/tag_corner_refiner.h"
#include "core/track/tag_detector.h"
#include "core/track/tag_pose_solver.h"

namespace arpipe {
namespace {

std::string config_source(const Config& config) {
  return config.file.empty() ? std::string("config") : config.file.string();
}

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

// Checks what the detector does not: the bundle layout and the acceptance thresholds.
void validate(const Config& config, const TagDetector& detector) {
  const TrackConfig& track = config.track;
  const std::string source = config_source(config);
  if (track.bundle.empty()) {
    throw ConfigError(fmt::format("{}: track.bundle: expected at least one tag", source));
  }
  std::unordered_map<int, size_t> first_index;
  for (size_t i = 0; i < track.bundle.size(); ++i) {
    const BundleTag& tag = track.bundle[i];
    if (tag.id < 0 || tag.id >= detector.code_count()) {
      throw ConfigError(fmt::format("{}: track.bundle[{}].id: expected 0 to {} for family {}, got {}", source, i,
                                    detector.code_count() - 1, detector.family(), tag.id));
    }
    if (const auto [it, inserted] = first_index.emplace(tag.id, i); !inserted) {
      throw ConfigError(fmt::format("{}: track.bundle[{}].id: tag {} is already track.bundle[{}]", source, i, tag.id,
                                    it->second));
    }
    if (!(tag.size_m > 0) || !std::isfinite(tag.size_m)) {
      throw ConfigError(fmt::format("{}: track.bundle[{}].size: expected a size > 0 m, got {}", source, i, tag.size_m));
    }
    if (!finite(tag.center_m) || !std::isfinite(tag.yaw_rad)) {
      throw ConfigError(fmt::format("{}: track.bundle[{}]: expected a finite centre and yaw", source, i));
    }
  }
  if (!(track.min_decision_margin >= 0) || !std::isfinite(track.min_decision_margin)) {
    throw ConfigError(fmt::format("{}: track.min_decision_margin: expected a number >= 0, got {}", source,
                                  track.min_decision_margin));
  }
  if (!(track.ambiguity_ratio >= 1) || !std::isfinite(track.ambiguity_ratio)) {
    throw ConfigError(
        fmt::format("{}: track.ambiguity_ratio: expected a number >= 1, got {}", source, track.ambiguity_ratio));
  }
}

}  // namespace

struct TagTracker::Impl {
  TrackConfig config;
  std::unique_ptr<TagDetector> detector;
  const TagCornerRefiner full_range_refiner{PixelFormat::GREY};
  const TagCornerRefiner limited_range_refiner{PixelFormat::YUYV};
  std::unordered_map<int, std::array<Vec3, 4>> world_corners_by_id;

  // Per-frame buffers, kept to avoid allocating on every frame.
  std::vector<uint8_t> grey;
  std::vector<TagObservation> detections;
  std::vector<TagCorrespondence> correspondences;
  std::vector<double> correspondence_margins;
  std::unordered_map<int, size_t> correspondence_by_id;

  std::optional<SE3> previous_pose;  // set only while the previous frame was tracked
  bool warned_size_mismatch = false;
  bool nothing_virtual = false;

  void track(FrameContext& ctx);
  // Returns a skip reason, or empty when the frame can be tracked.
  std::string why_not_trackable(const FrameContext& ctx);
};

TagTracker::TagTracker() : impl_(std::make_unique<Impl>()) {}
TagTracker::~TagTracker() = default;

void TagTracker::configure(const Config& config) {
  // Build everything first, so a refused config leaves the running one untouched.
  auto detector = std::make_unique<TagDetector>(config);
  validate(config, *detector);
  std::unordered_map<int, std::array<Vec3, 4>> world_corners_by_id;
  for (const BundleTag& tag : config.track.bundle) world_corners_by_id[tag.id] = bundle_tag_world_corners(tag);

  impl_->config = config.track;
  // Only the virtual objects need the pose today (light probes and shadows will too): with nothing
  // to draw, tracking is work the scene does not need.
  impl_->nothing_virtual = !config.render.enabled || config.render.objects.empty();
  impl_->detector = std::move(detector);
  impl_->world_corners_by_id = std::move(world_corners_by_id);
  // A new bundle may define a different world frame, so the old pose says nothing.
  impl_->previous_pose.reset();
  impl_->warned_size_mismatch = false;
}

std::string TagTracker::Impl::why_not_trackable(const FrameContext& ctx) {
  if (!detector) return "not configured";
  if (!config.enabled) return "disabled";
  if (nothing_virtual) return "nothing virtual in the scene";
  if (!ctx.camera_model) return "no camera model";
  if (ctx.camera.empty()) return "empty frame";
  if (ctx.camera_model->width() != ctx.camera.width || ctx.camera_model->height() != ctx.camera.height) {
    if (!warned_size_mismatch) {
      log::warn("track: the camera model is for {}x{} but frames are {}x{}; tracking is off", ctx.camera_model->width(),
                ctx.camera_model->height(), ctx.camera.width, ctx.camera.height);
      warned_size_mismatch = true;
    }
    return "camera model size mismatch";
  }
  return {};
}

void TagTracker::Impl::track(FrameContext& ctx) {
  const Frame& frame = ctx.camera;
  const uint8_t* pixels = frame.data.data();
  size_t stride = frame.bytes_per_line;
  if (frame.format != PixelFormat::GREY) {
    to_grey(frame, grey);
    pixels = grey.data();
    stride = static_cast<size_t>(frame.width);
  }
  detector->detect(pixels, frame.width, frame.height, stride, detections);
  const bool limited_range = frame.format == PixelFormat::YUYV || frame.format == PixelFormat::NV12;
  const TagCornerRefiner& refiner = limited_range ? limited_range_refiner : full_range_refiner;

  // One correspondence per bundle id; if a tag shows up twice (a reflection), the surer one counts.
  correspondences.clear();
  correspondence_margins.clear();
  correspondence_by_id.clear();
  for (TagObservation& observation : detections) {
    const auto world = world_corners_by_id.find(observation.id);
    const bool usable = world != world_corners_by_id.end() && observation.hamming <= config.max_hamming &&
                        observation.decision_margin >= config.min_decision_margin;
    // Only tags that count are refined (it costs a few hundred unprojections); the others keep
    // libapriltag's corners. A tag too small to refine keeps them as well.
    if (usable && config.refine_corners) {
      refiner.refine(pixels, frame.width, frame.height, stride, *ctx.camera_model, detector->border_cells(),
                     observation.corners);
    }
    ctx.pose.tags.push_back(observation);
    if (!usable) continue;
    const auto [slot, inserted] = correspondence_by_id.emplace(observation.id, correspondences.size());
    if (inserted) {
      correspondences.push_back({world->second, observation.corners});
      correspondence_margins.push_back(observation.decision_margin);
    } else if (observation.decision_margin > correspondence_margins[slot->second]) {
      correspondences[slot->second].pixels = observation.corners;
      correspondence_margins[slot->second] = observation.decision_margin;
    }
  }

  const auto solution = correspondences.empty()
                            ? std::nullopt
                            : solve_tag_pose(*ctx.camera_model, correspondences, config.ambiguity_ratio, previous_pose);
  if (!solution) {
    ctx.pose.state = TrackState::Lost;
    previous_pose.reset();
    log::debug("track: frame {}: lost ({} detections, {} of the bundle)", ctx.input_index, detections.size(),
               correspondences.size());
    return;
  }
  ctx.pose.state = TrackState::Tracking;
  ctx.pose.T_cam_world = solution->T_cam_world;
  ctx.pose.reprojection_rms_px = solution->reprojection_rms_px;
  ctx.pose.ambiguous = solution->ambiguous;
  ctx.pose.tags_used = solution->tags_used;
  previous_pose = solution->T_cam_world;
  log::debug("track: frame {}: {} tags, rms {:.3f} px{}", ctx.input_index, solution->tags_used,
             solution->reprojection_rms_px, solution->ambiguous ? ", ambiguous" : "");
}

void TagTracker::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  std::string skipped;
  ctx.pose = PoseEstimate{};
  try {
    skipped = impl_->why_not_trackable(ctx);
    if (skipped.empty()) {
      impl_->track(ctx);
    } else {
      impl_->previous_pose.reset();
    }
  } catch (const std::exception& e) {
    // Only allocation or conversion failures get here; one frame without a pose is the right outcome.
    log::debug("track: frame {}: {}", ctx.input_index, e.what());
    ctx.pose = PoseEstimate{};
    ctx.pose.state = TrackState::Lost;
    impl_->previous_pose.reset();
  }
  const double ms = milliseconds_since(start);
  try {
    ctx.record_timing("track", ms, std::move(skipped));
  } catch (...) {
    // Out of memory while recording a timing; the pose is still valid.
  }
}

}  // namespace arpipe
