// The pose that best reprojects known 3D points onto their undistorted image positions (least
// squares in normalised coordinates x/z, y/z), refined from a seed by Levenberg-Marquardt on SE(3).
// The tag pose solver's last step: OpenCV's solvePnPRefineLM does the same in ~50 us a call, most
// of it fixed overhead; this one takes a few for the 4-16 corners of a tag bundle.
#pragma once

#include <optional>
#include <vector>

#include "core/geometry/se3.h"

namespace arpipe {

// T_cam_world minimising sum |pi(T * world[i]) - normalized[i]|^2, from `seed`. Stops when a step
// moves the pose by less than 1e-12 (radians and the translation's own scale), after 100 steps, or
// when no step lowers the error any more. nullopt when the seed puts a point at or behind the
// camera or the sizes differ.
std::optional<SE3> refine_pose(const SE3& seed, const std::vector<Vec3>& world, const std::vector<Vec2>& normalized);

}  // namespace arpipe
