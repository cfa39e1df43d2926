// Shutter motion: the frame's exposure window and the camera poses over it.
#include "core/motion/shutter_motion.h"

#include <algorithm>
#include <cmath>

namespace arpipe {

int64_t ShutterTiming::row_start_ns(double row) const {
  if (rows <= 1 || readout_ns <= 0) return exposure_start_ns;
  const double fraction = std::clamp(row / double(rows - 1), 0.0, 1.0);
  return exposure_start_ns + std::llround(fraction * double(readout_ns));
}

ShutterTiming shutter_timing(const FrameMetadata& meta, int rows, int64_t default_exposure_ns) {
  ShutterTiming timing;
  timing.exposure_start_ns = meta.exposure_start_ns;
  timing.rows = std::max(rows, 1);
  timing.readout_ns = std::max<int64_t>(meta.readout_ns, 0);
  const int64_t interval = meta.frame_duration_ns;
  const bool usable = meta.exposure_ns > 0 && (interval <= 0 || meta.exposure_ns <= interval);
  if (usable) {
    timing.exposure_ns = meta.exposure_ns;
  } else {
    // The shutter cannot stay open longer than a frame, whatever the config says.
    timing.exposure_ns = interval > 0 ? std::min(default_exposure_ns, interval) : default_exposure_ns;
    timing.fallback_exposure = true;
  }
  return timing;
}

SE3 ShutterMotion::T_cam_world_at(int64_t t_ns) const {
  const int64_t start = timing.exposure_start_ns;
  const int64_t end = timing.end_ns();
  // Each half is one constant-velocity piece; a half of zero length borrows the other's velocity.
  if (t_ns <= pose_time_ns) {
    if (pose_time_ns > start) return pose_at_time({start, T_cam_world_start}, {pose_time_ns, T_cam_world_mid}, t_ns, method);
    if (end > pose_time_ns) return pose_at_time({pose_time_ns, T_cam_world_mid}, {end, T_cam_world_end}, t_ns, method);
    return T_cam_world_mid;
  }
  if (end > pose_time_ns) return pose_at_time({pose_time_ns, T_cam_world_mid}, {end, T_cam_world_end}, t_ns, method);
  if (pose_time_ns > start) return pose_at_time({start, T_cam_world_start}, {pose_time_ns, T_cam_world_mid}, t_ns, method);
  return T_cam_world_mid;
}

ShutterMotion estimate_shutter_motion(const ShutterTiming& timing, const TimedPose& current, const TimedPose* previous,
                                      const TimedPose* next, PoseInterpolation method) {
  ShutterMotion motion;
  motion.timing = timing;
  motion.fallback_exposure = timing.fallback_exposure;
  motion.method = method;
  motion.pose_time_ns = current.time_ns;
  motion.T_cam_world_mid = current.T_cam_world;
  // Neighbours at the same instant carry no velocity.
  if (previous && previous->time_ns >= current.time_ns) previous = nullptr;
  if (next && next->time_ns <= current.time_ns) next = nullptr;
  const int64_t start = timing.exposure_start_ns;
  const int64_t end = timing.end_ns();
  if (next) {
    const TimedPose& before = previous ? *previous : current;
    const TimedPose& after = previous ? current : *next;
    motion.T_cam_world_start = pose_at_time(before, after, start, method);
    motion.T_cam_world_end = pose_at_time(current, *next, end, method);
    motion.state = previous ? MotionState::Interpolated : MotionState::Extrapolated;
    return motion;
  }
  if (previous) {
    motion.T_cam_world_start = pose_at_time(*previous, current, start, method);
    motion.T_cam_world_end = pose_at_time(*previous, current, end, method);
    motion.state = MotionState::Extrapolated;
    return motion;
  }
  motion.state = MotionState::None;
  motion.why_none = "no neighbouring pose";
  return motion;
}

}  // namespace arpipe
