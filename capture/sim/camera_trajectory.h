// Where the simulated camera is at any instant: smooth interpolation of keyframes, or a seeded
// random smooth path whose speed gives a chosen amount of motion blur.
#pragma once

#include "capture/sim/sim_scene.h"
#include "core/geometry/se3.h"

namespace arpipe::sim {

class CameraTrajectory {
 public:
  // duration_s: from the first exposure start to the end of the last frame (the random path
  // covers it; keyframes hold their first/last pose outside their time range). seed: the
  // random path's seed. The trajectory was validated by the scene loader.
  CameraTrajectory(const SimTrajectory& trajectory, const SimCamera& camera, double duration_s, uint64_t seed);

  // T_cam_world at t seconds after the first frame's exposure start. Smooth: continuous in
  // position, rotation and their first derivatives.
  SE3 T_cam_world(double t_s) const;

 private:
  // (implementation's choice)
};

// The pose of a keyframe (camera x right, y down, z towards look_at; image up close to `up`).
SE3 keyframe_pose(const SimKeyframe& keyframe);

}  // namespace arpipe::sim
