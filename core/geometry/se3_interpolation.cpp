// SE(3) interpolation and extrapolation of camera poses: the centre-line and screw models.
#include "core/geometry/se3_interpolation.h"

namespace arpipe {

SE3 interpolate_camera_pose(const SE3& T_cam_world_a, const SE3& T_cam_world_b, double s, PoseInterpolation method) {
  if (method == PoseInterpolation::Screw) {
    // T_a exp(s log(T_a^-1 T_b)): the same curve whether the increment is taken in the camera or
    // the world frame, since T exp(X) T^-1 = exp(Ad_T X).
    const Vec6 twist = (T_cam_world_a.inverse() * T_cam_world_b).log();
    Vec6 scaled{};
    for (size_t i = 0; i < 6; ++i) scaled[i] = s * twist[i];
    return T_cam_world_a * SE3::exp(scaled);
  }
  // SE3::interpolate slerps the rotation and moves the translation on a straight line; on
  // T_world_cam that translation is the camera centre, which is the line we want (on T_cam_world
  // it would be -R c, which curves while the camera turns).
  return T_cam_world_a.inverse().interpolate(T_cam_world_b.inverse(), s).inverse();
}

double time_fraction(int64_t a_ns, int64_t b_ns, int64_t t_ns) { return double(t_ns - a_ns) / double(b_ns - a_ns); }

SE3 pose_at_time(const TimedPose& a, const TimedPose& b, int64_t t_ns, PoseInterpolation method) {
  return interpolate_camera_pose(a.T_cam_world, b.T_cam_world, time_fraction(a.time_ns, b.time_ns, t_ns), method);
}

}  // namespace arpipe
