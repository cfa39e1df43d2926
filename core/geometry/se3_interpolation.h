// Camera poses between and beyond timed samples: SE(3) interpolation and constant-velocity
// extrapolation for the shutter-motion stage (core/motion). No Euler angles anywhere.
#pragma once

#include <cstdint>

#include "core/geometry/se3.h"

namespace arpipe {

// How a camera moves between two poses.
//
// CentreLine (the default): the orientation turns at constant angular velocity (slerp) and the
//   camera centre moves on a straight line at constant speed. Over one frame interval a hand-held
//   or vehicle camera's centre moves on a near-straight line whatever it does with its rotation,
//   so this is the physical model (tests/track/shutter_motion_sim_test.cpp measures it against
//   the simulator's truth).
// Screw: the rigid-body geodesic T_a exp(s log(T_a^-1 T_b)). Rotation and translation are
//   coupled: while turning, the centre swings on a helix about the screw axis, which is right for
//   a camera on a turntable arm but bends a straight walk.
// The two agree exactly when the centre does not move or the rotation does not change, and to
// second order in the motion otherwise.
enum class PoseInterpolation { CentreLine, Screw };

// The camera pose T_cam_world at fraction s of the way from a (s = 0) to b (s = 1); s outside
// [0, 1] extrapolates at the same constant velocity. Exact at s = 0 and s = 1 (to rounding).
// Near 180 degrees of relative rotation the path follows the shorter way round (stable through
// quaternions); at exactly 180 degrees either way is a valid answer and one is returned.
SE3 interpolate_camera_pose(const SE3& T_cam_world_a, const SE3& T_cam_world_b, double s,
                            PoseInterpolation method = PoseInterpolation::CentreLine);

struct TimedPose {
  int64_t time_ns = 0;  // CLOCK_MONOTONIC, the instant the pose belongs to
  SE3 T_cam_world;
};

// The pose at time t on the constant-velocity motion through a and b (a.time_ns != b.time_ns):
// interpolation for t between them, constant-velocity extrapolation outside.
SE3 pose_at_time(const TimedPose& a, const TimedPose& b, int64_t t_ns,
                 PoseInterpolation method = PoseInterpolation::CentreLine);

// The fraction of the way from a to b that time t lies at. The differences are taken in integer
// nanoseconds first, so large CLOCK_MONOTONIC values lose nothing to rounding.
double time_fraction(int64_t a_ns, int64_t b_ns, int64_t t_ns);

}  // namespace arpipe
