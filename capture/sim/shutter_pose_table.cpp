// ShutterPoseTable: tabulation and lookup.
#include "capture/sim/shutter_pose_table.h"

#include <algorithm>
#include <cmath>

namespace arpipe::sim {

namespace {

RayPose ray_pose(const SE3& T_cam_world) {
  const SE3 T_world_cam = T_cam_world.inverse();
  RayPose pose;
  for (int i = 0; i < 3; ++i) {
    pose.centre[i] = T_world_cam.translation()[i];
    for (int j = 0; j < 3; ++j) pose.R_world_cam[i][j] = T_world_cam.rotation()[i][j];
  }
  return pose;
}

}  // namespace

ShutterPoseTable::ShutterPoseTable(const CameraTrajectory& trajectory, double start_s, double end_s, int intervals)
    : start_s_(start_s), step_s_(end_s > start_s ? (end_s - start_s) / intervals : 0.0) {
  const int count = step_s_ > 0 ? intervals + 1 : 1;
  entries_.reserve(size_t(count));
  for (int i = 0; i < count; ++i) entries_.push_back(ray_pose(trajectory.T_cam_world(start_s + i * step_s_)));
}

RayPose ShutterPoseTable::at(double t_s) const {
  if (entries_.size() == 1) return entries_[0];
  const double position = std::clamp((t_s - start_s_) / step_s_, 0.0, double(entries_.size() - 1));
  const size_t i = std::min(size_t(position), entries_.size() - 2);
  const double f = position - double(i);
  const RayPose& a = entries_[i];
  const RayPose& b = entries_[i + 1];
  RayPose out;
  for (int r = 0; r < 3; ++r) {
    out.centre[r] = a.centre[r] + f * (b.centre[r] - a.centre[r]);
    for (int c = 0; c < 3; ++c) out.R_world_cam[r][c] = a.R_world_cam[r][c] + f * (b.R_world_cam[r][c] - a.R_world_cam[r][c]);
  }
  return out;
}

}  // namespace arpipe::sim
