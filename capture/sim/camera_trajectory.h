// Where the simulated camera is at any instant: smooth interpolation of keyframes, or a seeded
// random smooth path whose speed gives a chosen amount of motion blur.
#pragma once

#include <cstdint>
#include <memory>

#include "capture/sim/sim_scene.h"
#include "core/geometry/se3.h"

namespace arpipe::sim {

class CameraTrajectory {
 public:
  // duration_s: from the first exposure start to the end of the last frame (the random path
  // covers it; keyframes hold their first/last pose outside their time range). seed: the
  // random path's seed. The trajectory was validated by the scene loader; this still throws
  // std::invalid_argument (naming the key) on no keyframes, times not increasing, or random-path
  // bounds out of order.
  //
  // Keyframes: the camera centre is a cubic Hermite spline with the keyframe times as knots and
  // three-point (non-uniform Catmull-Rom) tangents; the rotation is R_k exp(phi(t)) on each
  // segment, phi a cubic Hermite curve in the segment's tangent space whose end slopes match
  // the neighbouring segments' angular velocities (through the inverse right Jacobian), so the
  // angular velocity is continuous across knots. Velocity is zero at the first and last keyframe,
  // so holding the end poses stays C1.
  //
  // Random: an orbit about `target` (distance, elevation, azimuth and a small look-at wander are
  // sums of seeded sinusoids), image up = world +z projected, or the horizontal direction away
  // from the camera when looking straight down. Time is scaled so that the largest of
  // fx (|w_perp| + |v_perp| / distance) x the longest exposure over [0, duration_s] is max_blur_px
  // (w, v: angular and linear velocity of the camera; perp: across the optical axis; distance:
  // camera to target). fx: the model's fx (or its numerical focal length at the image centre).
  CameraTrajectory(const SimTrajectory& trajectory, const SimCamera& camera, double duration_s, uint64_t seed);

  // T_cam_world at t seconds after the first frame's exposure start. Smooth: continuous in
  // position, rotation and their first derivatives.
  SE3 T_cam_world(double t_s) const;

 private:
  struct Path;  // keyframe spline or random orbit
  std::shared_ptr<const Path> path_;
};

// The pose of a keyframe (camera x right, y down, z towards look_at; image up close to `up`).
// roll_rad turns the camera about z, x towards y: clockwise as the image is drawn (y down), so
// the scene appears to turn anticlockwise. When `up` is (nearly) parallel to the viewing
// direction, world +y (then +x) stands in for it. Throws std::invalid_argument when position
// and look_at coincide.
SE3 keyframe_pose(const SimKeyframe& keyframe);

}  // namespace arpipe::sim
