// Where a tag of the anchor bundle lies in the world frame: its pose and its four corners, in the
// corner order libapriltag reports (bottom-left, bottom-right, top-right, top-left of the printed tag).
#pragma once

#include <array>

#include "core/config/config.h"
#include "core/geometry/se3.h"

namespace arpipe {

// T_world_tag of a bundle tag, in the tag frame of docs/DESIGN.md (x right, y towards the printed top,
// z out of the face): a rotation by yaw about world z, then a shift to the tag's centre.
SE3 bundle_tag_pose(const BundleTag& tag);

// The corners (-s/2,-s/2), (s/2,-s/2), (s/2,s/2), (-s/2,s/2) of the tag frame, in world coordinates.
std::array<Vec3, 4> bundle_tag_world_corners(const BundleTag& tag);

}  // namespace arpipe
