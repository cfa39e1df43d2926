// Where the default capture's tag (configs/arpipe.toml: tag 0, 10 cm) is in a frame, from the
// simulator's true pose: for tests that check tracking against the truth.
#pragma once

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"

namespace arpipe::test {

inline constexpr double kTagSize = 0.1;

// Ground-truth visibility: every tag corner (with its white border) projects inside the image with a margin.
inline bool tag_fully_visible(const CameraModel& model, const SE3& T_cam_world, double margin_px) {
  const double h = kTagSize / 2 * 10.0 / 8.0;  // white border included
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      const Vec3 p = T_cam_world * Vec3{sx * h, sy * h, 0};
      if (p[2] <= 0) return false;
      const auto px = model.project(p);
      if (!px || (*px)[0] < margin_px || (*px)[1] < margin_px || (*px)[0] > model.width() - 1 - margin_px ||
          (*px)[1] > model.height() - 1 - margin_px)
        return false;
    }
  return true;
}

inline bool tag_out_of_view(const CameraModel& model, const SE3& T_cam_world) {
  const Vec3 c = T_cam_world * Vec3{0, 0, 0};
  if (c[2] <= 0) return true;
  const double h = kTagSize / 2 * 10.0 / 8.0;
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      const auto px = model.project(T_cam_world * Vec3{sx * h, sy * h, 0});
      if (px && (*px)[0] >= 0 && (*px)[1] >= 0 && (*px)[0] <= model.width() - 1 && (*px)[1] <= model.height() - 1)
        return false;
    }
  return true;
}

}  // namespace arpipe::test
