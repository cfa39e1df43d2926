// How the camera moved while one frame's shutter was open: its pose at exposure start, middle and
// end and at any row's exposure (rolling shutter), estimated from the timed poses of nearby frames.
#pragma once

#include <cstdint>
#include <string_view>

#include "core/config/choice_names.h"
#include "core/frame.h"
#include "core/geometry/se3_interpolation.h"

namespace arpipe {

enum class MotionState {
  None,          // no motion for this frame; ShutterMotion::why_none says why
  Interpolated,  // start and end lie between this frame's pose and its neighbours' (latency 1)
  Extrapolated,  // some of the window lies beyond the newest pose: constant velocity (latency 0)
};
inline constexpr ChoiceName<MotionState> kMotionStateNames[] = {{"none", MotionState::None},
                                                                 {"interpolated", MotionState::Interpolated},
                                                                 {"extrapolated", MotionState::Extrapolated}};
// The state's name in the results ("none", "interpolated", "extrapolated").
inline std::string_view motion_state_name(MotionState state) {
  return choice_name<MotionState>(kMotionStateNames, state);
}

// The exposure window of a frame, with the simulator's row timing (docs/SIMULATOR.md): row r
// starts exposing r/(rows-1) x readout after row 0, and every row is exposed for exposure_ns.
struct ShutterTiming {
  int64_t exposure_start_ns = 0;  // row 0 starts exposing
  int64_t exposure_ns = 0;        // per row, > 0
  int64_t readout_ns = 0;         // row 0 to the last row; 0 = global shutter
  int rows = 1;                   // image height
  bool fallback_exposure = false; // the metadata had no usable exposure; exposure_ns is the configured one

  int64_t end_ns() const { return exposure_start_ns + exposure_ns + readout_ns; }  // last row stops
  // Middle of the middle row's exposure (FrameMetadata::exposure_mid_ns).
  int64_t mid_ns() const { return exposure_start_ns + (exposure_ns + readout_ns) / 2; }
  int64_t row_start_ns(double row) const;  // fractional rows allowed; clamped to [0, rows-1]
  int64_t row_mid_ns(double row) const { return row_start_ns(row) + exposure_ns / 2; }
};

// The frame's timing from its metadata. An exposure <= 0 (unknown) or longer than a known frame
// interval is replaced by default_exposure_ns (itself capped at the frame interval) and flagged.
// A negative readout counts as 0.
ShutterTiming shutter_timing(const FrameMetadata& meta, int rows, int64_t default_exposure_ns);

struct ShutterMotion {
  MotionState state = MotionState::None;
  std::string_view why_none;  // a static phrase when state == None ("no pose: tracking lost", ...)
  bool fallback_exposure = false;  // copied from timing: the exposure time was the configured default
  ShutterTiming timing;

  int64_t pose_time_ns = 0;  // the instant the tracked pose of this frame belongs to
  SE3 T_cam_world_start;     // at timing.exposure_start_ns (row 0 starts)
  SE3 T_cam_world_mid;       // at pose_time_ns: the frame's tracked pose
  SE3 T_cam_world_end;       // at timing.end_ns() (the last row stops)
  PoseInterpolation method = PoseInterpolation::CentreLine;
  // The largest image motion of the reference points (anchor corners, object origins) while
  // their own row is exposed: the blur length in pixels, so later stages skip blur below 0.5 px.
  double max_image_motion_px = 0;

  bool valid() const { return state != MotionState::None; }
  // The pose at any instant of [start, end] (and beyond, on the same constant-velocity pieces):
  // the motion from start to mid and from mid to end, each at constant velocity.
  SE3 T_cam_world_at(int64_t t_ns) const;
  // The pose at the middle of a row's exposure: what a rolling shutter saw that row with.
  SE3 T_cam_world_at_row(double row) const { return T_cam_world_at(timing.row_mid_ns(row)); }
  SE3 T_cam_world_at_row_start(double row) const { return T_cam_world_at(timing.row_start_ns(row)); }
  SE3 T_cam_world_at_row_end(double row) const { return T_cam_world_at(timing.row_start_ns(row) + timing.exposure_ns); }
};

// The motion of one frame from its own timed pose and the nearest tracked neighbours (nullptr when
// there is none). With a next pose the window's two halves are interpolated on the segments
// previous-current and current-next (a missing previous extrapolates the first half backwards
// from current-next); without one, both halves follow the constant velocity of previous-current.
// With neither neighbour the result is None ("no neighbouring pose").
ShutterMotion estimate_shutter_motion(const ShutterTiming& timing, const TimedPose& current, const TimedPose* previous,
                                      const TimedPose* next, PoseInterpolation method = PoseInterpolation::CentreLine);

}  // namespace arpipe
