// The camera's pose over one frame's exposure window, tabulated finely enough that linear
// interpolation between entries is exact to far below a pixel: the per-sample pose lookup of the
// simulator's motion blur and rolling shutter.
#pragma once

#include <array>
#include <vector>

#include "capture/sim/camera_trajectory.h"

namespace arpipe::sim {

// A camera-to-world pose ready for casting rays: world direction = R * camera direction,
// origin = the camera centre.
struct RayPose {
  std::array<std::array<double, 3>, 3> R_world_cam{};
  std::array<double, 3> centre{};
};

class ShutterPoseTable {
 public:
  // Tabulates T_world_cam on [start_s, end_s] (trajectory time) in `intervals` equal steps.
  ShutterPoseTable(const CameraTrajectory& trajectory, double start_s, double end_s, int intervals = 256);

  // The pose at trajectory time t (clamped to the table), linearly interpolated between entries.
  // Over one step of a 40-pixel blur the rotation error of this is ~1e-8 rad.
  RayPose at(double t_s) const;

 private:
  double start_s_ = 0;
  double step_s_ = 0;
  std::vector<RayPose> entries_;
};

}  // namespace arpipe::sim
