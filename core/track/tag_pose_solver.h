// Camera pose from the corners of one or more square tags of known world position: one PnP solve
// over all corners (undistorted through the camera model), seeded by both IPPE solutions of the largest tag.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"

namespace arpipe {

// One square tag seen on this frame: its corners in the world and in the image, in the same order
// (libapriltag's: bottom-left, bottom-right, top-right, top-left of the printed tag).
struct TagCorrespondence {
  std::array<Vec3, 4> world;   // metres, world frame; must form a square
  std::array<Vec2, 4> pixels;  // as detected, distorted (raw image pixels)
  // The same corners undistorted (x/z, y/z) when the corner refiner has them already: then they
  // are used as they are instead of unprojecting the pixels again (mrcal's solve, ~20 us a corner).
  std::optional<std::array<Vec2, 4>> normalized;
};

struct PoseCandidate {
  SE3 T_cam_world;
  double reprojection_rms_px = 0;  // sqrt(mean over corners of the squared pixel distance)
};

struct TagPoseSolution {
  SE3 T_cam_world;
  double reprojection_rms_px = 0;
  bool ambiguous = false;  // two distinct minima fit within the ambiguity ratio; see solve_tag_pose
  int tags_used = 0;
  std::vector<PoseCandidate> candidates;  // the distinct local minima found, lowest error first
};

// Solves T_cam_world from every usable tag (a tag is unusable when a corner cannot be undistorted).
// The largest tag in the image seeds the solve with its two IPPE_SQUARE solutions; each seed is
// refined by Levenberg-Marquardt over all corners. When the worse candidate's error is within
// ambiguity_ratio times the better one's, the result is ambiguous and, if `previous` is given (the
// pose of the frame before, when it was tracked), the candidate with the smaller rotation to it wins;
// otherwise the lower error wins. Returns nullopt when no tag is usable or no solve succeeds.
// Never throws.
std::optional<TagPoseSolution> solve_tag_pose(const CameraModel& camera, const std::vector<TagCorrespondence>& tags,
                                              double ambiguity_ratio, const std::optional<SE3>& previous) noexcept;

}  // namespace arpipe
