// The track stage: AprilTag detection and the camera pose relative to the anchor (a tag or a bundle).
// World frame = anchor: x along the tag's right edge, y along its top edge, z out of its face.
#include "core/track/tag_tracker.h"

#include <fmt/format.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <vector>

#include "core/geometry/se3_interpolation.h"
#include "core/image/image_motion.h"
#include "core/image/pixel_convert.h"
#include "core/image/pixel_rect.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/track/bundle_tag_geometry.h"
#include "core/track/tag_corner_refiner.h"
#include "core/track/tag_detector.h"
#include "core/track/tag_pose_solver.h"

namespace arpipe {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

// Checks what the detector does not: the bundle layout and the acceptance thresholds.
void validate(const Config& config, const TagDetector& detector) {
  const TrackConfig& track = config.track;
  const std::string source = config_source_name(config);
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
  if (track.max_predicted_frames < 0 || track.max_predicted_frames > 30) {
    throw ConfigError(fmt::format("{}: track.max_predicted_frames: expected 0 to 30, got {}", source,
                                  track.max_predicted_frames));
  }
  if (!(track.ambiguity_ratio >= 1) || !std::isfinite(track.ambiguity_ratio)) {
    throw ConfigError(
        fmt::format("{}: track.ambiguity_ratio: expected a number >= 1, got {}", source, track.ambiguity_ratio));
  }
}

// The bundle's corners projected with a camera pose: their bounding box in pixels, and how many tags
// have all four corners inside the frame. nullopt when a corner is behind the camera or off the lens.
struct ProjectedBundle {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  int tags_in_frame = 0;
  double largest_tag_px = 0;  // the widest or tallest single tag's box
};

std::optional<ProjectedBundle> project_bundle(const CameraModel& camera, const SE3& T_cam_world,
                                              const std::unordered_map<int, std::array<Vec3, 4>>& world_corners) {
  ProjectedBundle bundle;
  for (const auto& [id, corners] : world_corners) {
    bool inside = true;
    double tx0 = 1e18, ty0 = 1e18, tx1 = -1e18, ty1 = -1e18;
    for (const Vec3& corner : corners) {
      const auto pixel = camera.project(T_cam_world * corner);
      if (!pixel) return std::nullopt;
      const double x = (*pixel)[0], y = (*pixel)[1];
      tx0 = std::min(tx0, x), ty0 = std::min(ty0, y), tx1 = std::max(tx1, x), ty1 = std::max(ty1, y);
      inside = inside && x >= 0 && y >= 0 && x <= camera.width() - 1 && y <= camera.height() - 1;
    }
    bundle.x0 = std::min(bundle.x0, tx0);
    bundle.y0 = std::min(bundle.y0, ty0);
    bundle.x1 = std::max(bundle.x1, tx1);
    bundle.y1 = std::max(bundle.y1, ty1);
    bundle.largest_tag_px = std::max({bundle.largest_tag_px, tx1 - tx0, ty1 - ty0});
    bundle.tags_in_frame += inside ? 1 : 0;
  }
  return bundle;
}

// The box grown by `margin` on each side, its left and top edges moved down and its right and bottom
// edges up to multiples of `align`, then clipped to the frame.
PixelRect grown_rect(const ProjectedBundle& box, double margin, int align, int width, int height) {
  const auto down = [align](double v) { return int(std::floor(v / align)) * align; };
  const auto up = [align](double v) { return int(std::ceil(v / align)) * align; };
  const int left = std::clamp(down(box.x0 - margin), 0, width);
  const int top = std::clamp(down(box.y0 - margin), 0, height);
  const int right = std::clamp(up(box.x1 + margin), 0, width);
  const int bottom = std::clamp(up(box.y1 + margin), 0, height);
  return PixelRect{left, top, right - left, bottom - top};
}

// libapriltag thresholds the decimated image in tiles of 4 pixels, each against the extremes of its
// 3x3 tiles; a window on that grid leaves every tile in it as the whole frame's.
int tile_grid_px(double quad_decimate) {
  const double whole = std::round(quad_decimate);
  // 1.5 takes 3 pixels to 2: 12 pixels per 4 decimated ones.
  return whole == quad_decimate ? 4 * int(whole) : 4 * 3 * int(std::ceil(quad_decimate));
}

// Where to look for the bundle on this frame, and how many of its tags should be found there.
struct SearchWindow {
  PixelRect rect;
  int tags_in_frame = 0;
};

}  // namespace

struct TagTracker::Impl {
  TrackConfig config;
  std::unique_ptr<TagDetector> detector;
  // The search near a prediction: the same detector at full resolution (quad_decimate 1), which
  // finds the smeared quads of a blurred tag that the decimated pass misses, run on a small crop.
  std::unique_ptr<TagDetector> crop_detector;
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
  // The last detection's tags' patch and pose (track.still_px), while frames since are tracked.
  struct StillReference {
    PixelRect box;
    SmoothedPatch smoothed;  // its luma, box.width x box.height, smoothed once for patch_motion
    PoseEstimate pose;
    std::optional<std::array<double, 4>> bundle_box;  // x0, y0, x1, y1 of the bundle projected with pose
  };
  std::optional<StillReference> still;
  // The last two measured poses at their frames' mid-exposure (older first), and the frames since
  // the newer one; prediction needs both.
  std::optional<TimedPose> measured_older, measured_newer;
  int frames_since_measured = 0;
  bool warned_size_mismatch = false;
  bool nothing_virtual = false;

  void track(FrameContext& ctx);
  void forget_motion() {
    previous_pose.reset();
    still.reset();
    measured_older.reset();
    measured_newer.reset();
    frames_since_measured = 0;
  }
  // Turns detections into correspondences of the bundle (refining their corners) and appends them
  // to ctx.pose.tags.
  void collect(FrameContext& ctx, const uint8_t* pixels, size_t stride);
  // Runs the crop detector on the predicted tags' box grown by a margin; fills `detections` in
  // full-frame pixels.
  void search_near(const FrameContext& ctx, const SE3& predicted, const uint8_t* pixels, size_t stride);
  // The frame's luma inside `rect`, converted into `grey` (the frame's size).
  const uint8_t* luma(const Frame& frame, const PixelRect& rect) {
    to_grey(frame, rect, grey);
    return grey.data();
  }
  // Runs `with` on the rectangle of the image; fills `detections` in full-frame pixels.
  void detect_in(TagDetector& with, const PixelRect& rect, const uint8_t* pixels, size_t stride);
  // The frame's search window (track.search_window) for a camera at `expected`, with how many of
  // the bundle's tags should lie wholly inside the frame; nullopt when the window would be most of
  // the frame anyway, or the bundle does not project.
  std::optional<SearchWindow> search_window_at(const FrameContext& ctx, const SE3& expected) const;
  // Whether the last detection's patch is unchanged in this frame (then ctx.pose is its pose).
  bool keep_still_pose(FrameContext& ctx, const std::optional<SE3>& predicted, const uint8_t*& pixels, size_t stride,
                       bool needs_luma, int64_t time_ns);
  // Keeps this detection's patch and pose for the frames after it.
  void remember_still(const FrameContext& ctx, const uint8_t* pixels, size_t stride);
  // Records a pose measured (or kept) at time_ns for the prediction.
  void measured(const SE3& T_cam_world, int64_t time_ns);
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
  // The search needs a prediction, so without one the second detector (and its decode table) is
  // not built.
  std::unique_ptr<TagDetector> crop_detector;
  if (config.track.max_predicted_frames > 0) {
    Config crop_config = config;
    crop_config.track.quad_decimate = 1;
    crop_detector = std::make_unique<TagDetector>(crop_config);
  }
  impl_->crop_detector = std::move(crop_detector);
  impl_->detector = std::move(detector);
  impl_->world_corners_by_id = std::move(world_corners_by_id);
  // A new bundle may define a different world frame, so the old pose says nothing.
  impl_->forget_motion();
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

void TagTracker::Impl::collect(FrameContext& ctx, const uint8_t* pixels, size_t stride) {
  const Frame& frame = ctx.camera;
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
    std::optional<std::array<Vec2, 4>> normalized;
    if (usable && config.refine_corners) {
      std::array<Vec2, 4> undistorted;
      if (refiner.refine(pixels, frame.width, frame.height, stride, *ctx.camera_model, detector->border_cells(),
                         observation.corners, &undistorted))
        normalized = undistorted;
    }
    ctx.pose.tags.push_back(observation);
    if (!usable) continue;
    const auto [slot, inserted] = correspondence_by_id.emplace(observation.id, correspondences.size());
    if (inserted) {
      correspondences.push_back({world->second, observation.corners, normalized});
      correspondence_margins.push_back(observation.decision_margin);
    } else if (observation.decision_margin > correspondence_margins[slot->second]) {
      correspondences[slot->second].pixels = observation.corners;
      correspondences[slot->second].normalized = normalized;
      correspondence_margins[slot->second] = observation.decision_margin;
    }
  }
}

void TagTracker::Impl::detect_in(TagDetector& with, const PixelRect& rect, const uint8_t* pixels, size_t stride) {
  with.detect(pixels + size_t(rect.y) * stride + size_t(rect.x), rect.width, rect.height, stride, detections);
  for (TagObservation& observation : detections) {
    for (Vec2& corner : observation.corners) {
      corner[0] += rect.x;
      corner[1] += rect.y;
    }
  }
}

void TagTracker::Impl::search_near(const FrameContext& ctx, const SE3& predicted, const uint8_t* pixels,
                                   size_t stride) {
  detections.clear();
  const Frame& frame = ctx.camera;
  const auto box = project_bundle(*ctx.camera_model, predicted, world_corners_by_id);
  if (!box) return;  // behind the camera or off the lens: nothing sensible to search
  // The margin covers the prediction's error and the blur's smear: half the box again each side,
  // and at least 40 px (the fastest pans of configs/sim/tag-pan.toml smear 20-30 px).
  const double margin = std::max(40.0, 0.5 * std::max(box->x1 - box->x0, box->y1 - box->y0));
  const PixelRect rect = grown_rect(*box, margin, 1, frame.width, frame.height);
  if (rect.width < 16 || rect.height < 16) return;
  detect_in(*crop_detector, rect, pixels, stride);
}

std::optional<SearchWindow> TagTracker::Impl::search_window_at(const FrameContext& ctx, const SE3& expected) const {
  const Frame& frame = ctx.camera;
  const auto box = project_bundle(*ctx.camera_model, expected, world_corners_by_id);
  if (!box || box->tags_in_frame == 0) return std::nullopt;
  // Half the largest tag and at least 40 px: it holds the constant-velocity prediction's error on
  // the blur captures' fastest turns, and libapriltag's own 3x3-tile neighbourhood. (Not half the
  // whole bundle's box, which for tags spread apart would make the window most of the frame.)
  const double margin = std::max(40.0, 0.5 * box->largest_tag_px);
  const PixelRect rect = grown_rect(*box, margin, tile_grid_px(config.quad_decimate), frame.width, frame.height);
  // A window of most of the frame saves little and may cut a tag the prediction misplaced.
  if (rect.width < 16 || rect.height < 16 || double(rect.width) * rect.height > 0.5 * frame.width * frame.height)
    return std::nullopt;
  return SearchWindow{rect, box->tags_in_frame};
}

bool TagTracker::Impl::keep_still_pose(FrameContext& ctx, const std::optional<SE3>& predicted, const uint8_t*& pixels,
                                       size_t stride, bool needs_luma, int64_t time_ns) {
  if (!(config.still_px > 0) || !still || !previous_pose) return false;
  const Frame& frame = ctx.camera;
  // A camera still moving by the last two measurements is not checked: it would pay for the check
  // and then for the detection. (It must slow down first: a kept pose predicts no motion.)
  if (predicted) {
    const auto moved = project_bundle(*ctx.camera_model, *predicted, world_corners_by_id);
    const auto& kept = still->bundle_box;
    if (!moved || !kept || std::max({std::abs(moved->x0 - (*kept)[0]), std::abs(moved->y0 - (*kept)[1]),
                                     std::abs(moved->x1 - (*kept)[2]), std::abs(moved->y1 - (*kept)[3])}) > 0.5)
      return false;
  }
  const PixelRect& box = still->box;
  if (box.right() > frame.width || box.bottom() > frame.height) return false;
  if (needs_luma) pixels = luma(frame, box);
  const uint8_t* current = pixels + size_t(box.y) * stride + size_t(box.x);
  const std::optional<PatchMotion> motion =
      patch_motion(still->smoothed, current, stride);
  // More than this share of pixels the motion cannot explain: something crossed the tags. More
  // than this change of contrast: not the same picture (a flat one fits with a gain of -1), or an
  // exposure step worth detecting again.
  constexpr double kMaxOutlierFraction = 0.005;
  constexpr double kMaxGain = 0.25;
  if (!motion || !(motion->max_corner_px < config.still_px) || !(motion->outlier_fraction < kMaxOutlierFraction) ||
      !(std::abs(motion->gain) < kMaxGain))
    return false;
  ctx.pose = still->pose;
  ctx.pose.image_still = true;
  ctx.pose.searched_window_only = false;  // nothing was searched
  measured(ctx.pose.T_cam_world, time_ns);
  log::debug("track: frame {}: still ({:.3f} px since the last detection)", ctx.input_index, motion->max_corner_px);
  return true;
}

void TagTracker::Impl::remember_still(const FrameContext& ctx, const uint8_t* pixels, size_t stride) {
  still.reset();
  if (!(config.still_px > 0) || ctx.pose.tags.empty()) return;
  const Frame& frame = ctx.camera;
  ProjectedBundle box;
  for (const TagObservation& tag : ctx.pose.tags)
    for (const Vec2& corner : tag.corners) {
      box.x0 = std::min(box.x0, corner[0]);
      box.y0 = std::min(box.y0, corner[1]);
      box.x1 = std::max(box.x1, corner[0]);
      box.y1 = std::max(box.y1, corner[1]);
    }
  // A few pixels beyond the corners: the border's outer edges are in it, whichever way it moves.
  const PixelRect rect = grown_rect(box, 4.0, 1, frame.width, frame.height);
  if (rect.width < 16 || rect.height < 16) return;
  StillReference reference{rect, smoothed_patch(pixels + size_t(rect.y) * stride + size_t(rect.x), stride, rect.width,
                                                 rect.height),
                            ctx.pose, {}};
  if (const auto kept = project_bundle(*ctx.camera_model, ctx.pose.T_cam_world, world_corners_by_id))
    reference.bundle_box = std::array<double, 4>{kept->x0, kept->y0, kept->x1, kept->y1};
  still = std::move(reference);
}

void TagTracker::Impl::measured(const SE3& T_cam_world, int64_t time_ns) {
  previous_pose = T_cam_world;
  if (measured_newer && time_ns > measured_newer->time_ns) {
    measured_older = measured_newer;
  } else {
    measured_older.reset();  // times out of order: no velocity from these two
  }
  measured_newer = TimedPose{time_ns, T_cam_world};
  frames_since_measured = 0;
}

void TagTracker::Impl::track(FrameContext& ctx) {
  const Frame& frame = ctx.camera;
  const uint8_t* pixels = frame.data.data();
  size_t stride = frame.bytes_per_line;
  // Other formats' luma is taken (luma()) only where the detector and the refiner will look: the
  // window, or the whole frame.
  const bool needs_luma = frame.format != PixelFormat::GREY;
  if (needs_luma) stride = static_cast<size_t>(frame.width);
  const int64_t time_ns = frame.meta.exposure_mid_ns();
  // Dropped frames count: the prediction reaches that much further. (Capped so it cannot overflow.)
  frames_since_measured = std::min(frames_since_measured + 1 + int(std::min<uint64_t>(ctx.dropped_before, 1000)),
                                   1'000'000);

  // The constant-velocity prediction for this frame, while the last measurement is recent enough.
  std::optional<SE3> predicted;
  if (config.max_predicted_frames > 0 && measured_older && measured_newer &&
      frames_since_measured <= config.max_predicted_frames && measured_newer->time_ns != measured_older->time_ns &&
      time_ns > measured_newer->time_ns) {
    predicted = pose_at_time(*measured_older, *measured_newer, time_ns);
  }

  // A still camera: the tags have not moved since they were last detected.
  if (keep_still_pose(ctx, predicted, pixels, stride, needs_luma, time_ns)) return;

  // After a tracked frame the bundle is most likely near where the motion puts it: the window
  // suffices when it holds every tag of the bundle that should be in the frame.
  std::optional<TagPoseSolution> solution;
  std::optional<SearchWindow> window;
  if (config.search_window && previous_pose) window = search_window_at(ctx, predicted ? *predicted : *previous_pose);
  if (window) {
    if (needs_luma) pixels = luma(frame, window->rect);
    detect_in(*detector, window->rect, pixels, stride);
    collect(ctx, pixels, stride);
    if (!correspondences.empty())
      solution = solve_tag_pose(*ctx.camera_model, correspondences, config.ambiguity_ratio, previous_pose);
    if (solution && solution->tags_used >= window->tags_in_frame) {
      ctx.pose.searched_window_only = true;
    } else {
      solution.reset();
      ctx.pose.tags.clear();
    }
  }
  if (!ctx.pose.searched_window_only) {
    if (needs_luma) pixels = luma(frame, PixelRect::full(frame.width, frame.height));
    detector->detect(pixels, frame.width, frame.height, stride, detections);
    collect(ctx, pixels, stride);
    if (!correspondences.empty())
      solution = solve_tag_pose(*ctx.camera_model, correspondences, config.ambiguity_ratio, previous_pose);
  }
  bool searched = false;
  if (!solution && predicted && crop_detector) {
    // Search near the prediction: a blurred tag the full-frame pass missed.
    searched = true;
    search_near(ctx, *predicted, pixels, stride);
    collect(ctx, pixels, stride);
    if (!correspondences.empty()) {
      solution = solve_tag_pose(*ctx.camera_model, correspondences, config.ambiguity_ratio, predicted);
    }
  }
  if (!solution && predicted) {
    // The uncertainty model: the displacement extrapolated since the last measurement, that is the
    // error if the camera had stopped at it. It grows linearly with the frames predicted, needs no
    // history beyond the two poses, and is what a renderer can compare with a threshold. It is not
    // a bound: a reversal costs more (2.5-3.3x on tag-pan, where the pan turns and speeds up).
    ctx.pose.state = TrackState::Predicted;
    ctx.pose.T_cam_world = *predicted;
    ctx.pose.frames_since_measured = frames_since_measured;
    ctx.pose.predicted_uncertainty_deg =
        rotation_angle_between(*predicted, measured_newer->T_cam_world) * 180.0 / std::numbers::pi;
    ctx.pose.predicted_uncertainty_mm =
        1e3 * norm(predicted->inverse().translation() - measured_newer->T_cam_world.inverse().translation());
    previous_pose.reset();
    still.reset();
    log::debug("track: frame {}: predicted, {} frames since measured (+-{:.2f} deg, {:.1f} mm)", ctx.input_index,
               frames_since_measured, ctx.pose.predicted_uncertainty_deg, ctx.pose.predicted_uncertainty_mm);
    return;
  }
  if (!solution) {
    ctx.pose.state = TrackState::Lost;
    previous_pose.reset();
    still.reset();
    // Once the prediction has run out, the old motion says nothing about the next acquisition.
    if (frames_since_measured > config.max_predicted_frames) {
      measured_older.reset();
      measured_newer.reset();
    }
    log::debug("track: frame {}: lost ({} detections, {} of the bundle)", ctx.input_index, detections.size(),
               correspondences.size());
    return;
  }
  ctx.pose.state = TrackState::Tracking;
  ctx.pose.T_cam_world = solution->T_cam_world;
  ctx.pose.reprojection_rms_px = solution->reprojection_rms_px;
  ctx.pose.ambiguous = solution->ambiguous;
  ctx.pose.tags_used = solution->tags_used;
  measured(solution->T_cam_world, time_ns);
  remember_still(ctx, pixels, stride);
  log::debug("track: frame {}: {} tags, rms {:.3f} px{}{}", ctx.input_index, solution->tags_used,
             solution->reprojection_rms_px, solution->ambiguous ? ", ambiguous" : "",
             searched ? ", found near the prediction" : "");
}

bool TagTracker::can_run_ahead() const noexcept { return !impl_->nothing_virtual; }

void TagTracker::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  std::string skipped;
  ctx.pose = PoseEstimate{};
  if (ctx.camera.meta.known_T_cam_world) {
    // The source knows where its camera looked (a panorama's view): nothing to detect.
    ctx.pose.state = TrackState::Tracking;
    ctx.pose.T_cam_world = *ctx.camera.meta.known_T_cam_world;
    try {
      ctx.record_timing("track", milliseconds_since(start), "pose given by the source");
    } catch (...) {
    }
    return;
  }
  try {
    skipped = impl_->why_not_trackable(ctx);
    if (skipped.empty()) {
      impl_->track(ctx);
    } else {
      impl_->forget_motion();
    }
  } catch (const std::exception& e) {
    // Only allocation or conversion failures get here; one frame without a pose is the right outcome.
    log::debug("track: frame {}: {}", ctx.input_index, e.what());
    ctx.pose = PoseEstimate{};
    ctx.pose.state = TrackState::Lost;
    impl_->forget_motion();
  }
  const double ms = milliseconds_since(start);
  try {
    ctx.record_timing("track", ms, std::move(skipped));
  } catch (...) {
    // Out of memory while recording a timing; the pose is still valid.
  }
}

}  // namespace arpipe
