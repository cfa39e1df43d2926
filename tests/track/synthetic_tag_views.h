// Test helpers for the track tests: camera models, random camera poses looking at the anchor, and
// tag corners projected exactly through the camera model (the ground truth the solver must recover).
#pragma once

#include <optional>
#include <random>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/track/tag_pose_solver.h"

namespace arpipe::test {

CameraModel pinhole_640x480();
// A wide-ish lens with clear radial, tangential and rational distortion (about 13% at the corners).
CameraModel opencv8_640x480();

// The camera centre sits at `distance` from `target` (world frame), `tilt` away from the world z
// axis (the tag normal) at azimuth `azimuth`, looking at `target`, turned by `roll` about its axis.
SE3 look_at(const Vec3& target, double distance, double tilt, double azimuth, double roll);

struct ViewRange {
  double min_distance = 0.2, max_distance = 2.0;
  double min_tilt = 0, max_tilt = 1.0471975511965976;  // 60 degrees
  double target_jitter = 0.02;                          // metres around the origin
};

// The correspondences of the bundle's tags seen from T_cam_world, with Gaussian pixel noise of
// sigma_px per coordinate; nullopt when a corner falls outside the image (with a 4 px margin).
std::optional<std::vector<TagCorrespondence>> project_bundle(const CameraModel& camera, const SE3& T_cam_world,
                                                             const std::vector<BundleTag>& bundle, double sigma_px,
                                                             std::mt19937_64& rng);

// A random view from `range` in which every corner of the bundle is inside the image.
SE3 random_view(const CameraModel& camera, const std::vector<BundleTag>& bundle, const ViewRange& range,
                std::mt19937_64& rng);

// Four tags of different sizes and yaws around the origin, as a printed bundle sheet might hold them.
std::vector<BundleTag> four_tag_bundle();

}  // namespace arpipe::test
