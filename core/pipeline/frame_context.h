// Everything the pipeline knows about one frame, passed from stage to stage and on to the sinks.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/light/light_estimate.h"
#include "core/motion/shutter_motion.h"
#include "core/pipeline/object_report.h"

namespace arpipe {

enum class TrackState {
  NotRun,    // tracking disabled or skipped
  Tracking,   // pose measured on this frame
  Predicted,  // no anchor tag found; pose extrapolated at constant velocity from the last two measured
  Lost,       // no anchor tag found on this frame (and none recently enough to predict from)
};
std::string_view track_state_name(TrackState state);

struct TagObservation {
  int id = 0;
  std::array<Vec2, 4> corners{};  // pixels, AprilTag order: bottom-left, bottom-right, top-right, top-left
  double decision_margin = 0;
  int hamming = 0;
};

struct PoseEstimate {
  TrackState state = TrackState::NotRun;
  SE3 T_cam_world;              // valid when state == Tracking or Predicted
  double reprojection_rms_px = 0;
  bool ambiguous = false;       // IPPE's two solutions were close; temporal consistency chose
  int tags_used = 0;
  // Predicted only: frames since the last measured pose (0 when Tracking), and how far the
  // prediction may be off. The growth model (tag_tracker.cpp): the displacement extrapolated since
  // the last measurement, i.e. the error if the camera had stopped there; linear in the time.
  int frames_since_measured = 0;
  double predicted_uncertainty_deg = 0;
  double predicted_uncertainty_mm = 0;  // camera centre
  // Every detection of the bundle's family on this frame; only those inside the search window
  // when the window sufficed (searched_window_only).
  std::vector<TagObservation> tags;
  // The detector ran only on the window around the expected bundle (track.search_window), and
  // that found every tag of the bundle expected in view.
  bool searched_window_only = false;
  // The tags' patch had not moved since the last detection (track.still_px): this is that
  // detection's pose and tags, not detected again.
  bool image_still = false;
};

struct StageTiming {
  std::string stage;
  double ms = 0;
  std::string skipped;  // empty when the stage ran; otherwise why it returned at once
};

// The virtual layer as the render stage hands it to the composite stage: a GL texture at the output
// image's size, linear with premultiplied alpha, image row v on GL row v, that holds the layer inside
// the rectangle (x, y, rect_width, rect_height). The texture belongs to the render stages' GL
// session, which keeps it alive; its name is good on the processing thread only, until the render
// stage draws the next frame (the runner runs the composite stage right after it), never in a sink.
struct VirtualLayerTexture {
  uint32_t texture = 0;  // a GLuint; 0: none
  int width = 0;
  int height = 0;
  int x = 0;
  int y = 0;
  int rect_width = 0;
  int rect_height = 0;
  // Which drawing this is: a new number (never 0) each time the render stage draws, the same when
  // it hands the last layer on again, so the composite need not read it back again.
  uint64_t generation = 0;
};

struct FrameContext {
  Frame camera;                                 // the input frame, in the source's pixel format
  std::shared_ptr<const CameraModel> camera_model;
  PoseEstimate pose;
  // The camera's motion over this frame's exposure (the motion stage); state None until then.
  ShutterMotion motion;
  // The light (the light stage); state None when no light stage ran: the renderer then uses the
  // config's fixed light.
  LightEstimate light;
  Frame output;                                 // the composited frame, RGB24; empty until composed
  // The camera frame as it was, RGB24, converted ahead of the composite stage on the helper thread
  // (pipeline.overlap_first_stage; Stage::process_ahead), and how long that took; empty when not.
  Frame camera_rgb24;
  double camera_rgb24_ms = 0;
  // The lens that ctx.output is seen through: camera_model, or its pinhole core when render.lens
  // is "undistort" (the output is then an undistorted picture). Set with ctx.output.
  std::shared_ptr<const CameraModel> output_camera_model;
  bool virtual_layer_drawn = false;
  // The virtual layer the render stage drew, for the composite stage (set with virtual_layer_drawn).
  VirtualLayerTexture virtual_layer;
  // How the virtual layer was drawn: "off" (sharp) or the render.blur method used, and its samples.
  std::string blur_method = "off";
  int blur_samples = 0;
  // Per virtual object, where it is and how much the proxies hid (the render stage; empty unless
  // the config has proxies or physics).
  std::vector<ObjectReport> objects;
  std::optional<PhysicsReport> physics;  // with a physics world (render.objects[].physics)
  std::optional<AnimationReport> animation;  // with animated proxies (render.proxies[].node)
  std::vector<StageTiming> timings;
  uint64_t input_index = 0;                     // position in the stream as the pipeline saw it
  uint64_t dropped_before = 0;                  // frames lost just before this one (sequence gap or queue drop)
  int64_t arrived_ns = 0;                       // CLOCK_MONOTONIC when the source handed the frame over

  // Where end-to-end latency counts from: the end of the exposure (the last row's) when the source's
  // timestamps are on this clock and at most 10 s before arrival (a live camera); otherwise the
  // arrival (a replay, whose recorded times are not now).
  int64_t latency_origin_ns() const;

  void record_timing(std::string stage, double ms, std::string skipped = {}) {
    timings.push_back({std::move(stage), ms, std::move(skipped)});
  }
};

}  // namespace arpipe
