// Where a tag of the anchor bundle lies in the world frame: its pose and its four corners, in the
// corner order libapriltag reports (bottom-left, bottom-right, top-right, top-left of the printed tag).
#include "core/track/bundle_tag_geometry.h"

#include <cmath>

namespace arpipe {

SE3 bundle_tag_pose(const BundleTag& tag) {
  const double c = std::cos(tag.yaw_rad);
  const double s = std::sin(tag.yaw_rad);
  const Mat3 yaw{{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
  return SE3(yaw, tag.center_m);
}

std::array<Vec3, 4> bundle_tag_world_corners(const BundleTag& tag) {
  const double h = tag.size_m / 2;
  const SE3 T_world_tag = bundle_tag_pose(tag);
  return {T_world_tag * Vec3{-h, -h, 0}, T_world_tag * Vec3{h, -h, 0}, T_world_tag * Vec3{h, h, 0},
          T_world_tag * Vec3{-h, h, 0}};
}

}  // namespace arpipe
