// Camera pose from the corners of one or more square tags of known world position: one PnP solve
// over all corners (undistorted through the camera model), seeded by both IPPE solutions of the largest tag.
#include "core/track/tag_pose_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "core/log.h"
#include "core/track/pose_refinement.h"

namespace arpipe {
namespace {

// Two refined seeds closer than this landed in the same minimum: LM converges far tighter, and
// genuinely distinct minima this close would make the same picture anyway.
constexpr double kSameMinimumRotationRad = 1e-4;
constexpr double kSameMinimumRelativeTranslation = 1e-4;

struct UndistortedTag {
  const TagCorrespondence* tag = nullptr;
  std::array<cv::Point2d, 4> normalized;  // pinhole coordinates x/z, y/z
  double image_area = 0;                  // in normalised units, to pick the seed tag
};

SE3 se3_from_cv(const cv::Mat& rvec, const cv::Mat& tvec) {
  return SE3::from_rt({rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)},
                      {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)});
}

// T_world_tag of a square from its world corners (BL, BR, TR, TL), in the tag frame of docs/DESIGN.md,
// and its edge length.
SE3 square_pose_in_world(const std::array<Vec3, 4>& w, double& edge) {
  const Vec3 center = 0.25 * (w[0] + w[1] + w[2] + w[3]);
  const Vec3 x = normalized((w[1] - w[0]) + (w[2] - w[3]));
  const Vec3 y_rough = (w[3] - w[0]) + (w[2] - w[1]);
  const Vec3 z = normalized(cross(x, y_rough));
  const Vec3 y = cross(z, x);
  edge = 0.25 * (norm(w[1] - w[0]) + norm(w[2] - w[1]) + norm(w[3] - w[2]) + norm(w[0] - w[3]));
  const Mat3 R{{{x[0], y[0], z[0]}, {x[1], y[1], z[1]}, {x[2], y[2], z[2]}}};
  return SE3(R, center);
}

double polygon_area(const std::array<cv::Point2d, 4>& p) {
  double twice_area = 0;
  for (size_t i = 0; i < 4; ++i) twice_area += p[i].cross(p[(i + 1) % 4]);
  return std::abs(twice_area) / 2;
}

// Both IPPE_SQUARE solutions of one tag, as T_cam_world.
std::vector<SE3> ippe_square_candidates(const UndistortedTag& seed) {
  double edge = 0;
  const SE3 T_world_tag = square_pose_in_world(seed.tag->world, edge);
  // IPPE_SQUARE wants its corners in AprilTag's own frame (x right, y down, z into the tag), which is
  // ours turned 180 degrees about x; libapriltag's corner order matches this list.
  const double h = edge / 2;
  const std::vector<cv::Point3d> object{{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0}};
  const std::vector<cv::Point2d> image(seed.normalized.begin(), seed.normalized.end());
  std::vector<cv::Mat> rvecs, tvecs;
  cv::solvePnPGeneric(object, image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvecs, tvecs, false,
                      cv::SOLVEPNP_IPPE_SQUARE);
  const SE3 T_apriltag_ours(Mat3{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}, Vec3{0, 0, 0});
  std::vector<SE3> seeds;
  for (size_t i = 0; i < rvecs.size(); ++i) {
    const SE3 T_cam_apriltag = se3_from_cv(rvecs[i], tvecs[i]);
    seeds.push_back(T_cam_apriltag * T_apriltag_ours * T_world_tag.inverse());
  }
  return seeds;
}

double reprojection_rms_px(const CameraModel& camera, const SE3& T_cam_world, const std::vector<UndistortedTag>& tags) {
  double sum_squared = 0;
  size_t count = 0;
  for (const auto& tag : tags) {
    for (size_t c = 0; c < 4; ++c) {
      const auto pixel = camera.project(T_cam_world * tag.tag->world[c]);
      if (!pixel) return std::numeric_limits<double>::infinity();
      const double dx = (*pixel)[0] - tag.tag->pixels[c][0];
      const double dy = (*pixel)[1] - tag.tag->pixels[c][1];
      sum_squared += dx * dx + dy * dy;
      ++count;
    }
  }
  return std::sqrt(sum_squared / static_cast<double>(count));
}

bool same_minimum(const SE3& a, const SE3& b) {
  const double scale = std::max(norm(a.translation()), 1e-9);
  return rotation_angle_between(a, b) < kSameMinimumRotationRad &&
         norm(a.translation() - b.translation()) < kSameMinimumRelativeTranslation * scale;
}

std::optional<TagPoseSolution> solve(const CameraModel& camera, const std::vector<TagCorrespondence>& tags,
                                     double ambiguity_ratio, const std::optional<SE3>& previous) {
  std::vector<UndistortedTag> usable;
  for (const auto& tag : tags) {
    UndistortedTag undistorted{&tag, {}, 0};
    bool ok = true;
    for (size_t c = 0; c < 4 && ok; ++c) {
      const auto n = tag.normalized ? std::optional<Vec2>((*tag.normalized)[c]) : camera.normalize(tag.pixels[c]);
      ok = n.has_value() && std::isfinite((*n)[0]) && std::isfinite((*n)[1]);
      if (ok) undistorted.normalized[c] = {(*n)[0], (*n)[1]};
    }
    if (!ok) continue;
    undistorted.image_area = polygon_area(undistorted.normalized);
    if (undistorted.image_area > 0) usable.push_back(undistorted);
  }
  if (usable.empty()) return std::nullopt;
  std::sort(usable.begin(), usable.end(),
            [](const UndistortedTag& a, const UndistortedTag& b) { return a.image_area > b.image_area; });

  std::vector<Vec3> world_points;
  std::vector<Vec2> image_points;
  for (const auto& tag : usable) {
    for (size_t c = 0; c < 4; ++c) {
      world_points.push_back(tag.tag->world[c]);
      image_points.push_back({tag.normalized[c].x, tag.normalized[c].y});
    }
  }

  // The largest tag gives the best-conditioned seeds; fall back to the next when IPPE fails.
  std::vector<SE3> seeds;
  for (const auto& tag : usable) {
    seeds = ippe_square_candidates(tag);
    if (!seeds.empty()) break;
  }

  std::vector<PoseCandidate> candidates;
  for (const SE3& seed : seeds) {
    const std::optional<SE3> minimum = refine_pose(seed, world_points, image_points);
    if (!minimum) continue;
    const SE3& refined = *minimum;
    const double error = reprojection_rms_px(camera, refined, usable);
    if (!std::isfinite(error)) continue;
    const auto duplicate = std::find_if(candidates.begin(), candidates.end(), [&](const PoseCandidate& c) {
      return same_minimum(c.T_cam_world, refined);
    });
    if (duplicate == candidates.end()) {
      candidates.push_back({refined, error});
    } else if (error < duplicate->reprojection_rms_px) {
      *duplicate = {refined, error};
    }
  }
  if (candidates.empty()) return std::nullopt;
  std::sort(candidates.begin(), candidates.end(),
            [](const PoseCandidate& a, const PoseCandidate& b) { return a.reprojection_rms_px < b.reprojection_rms_px; });

  TagPoseSolution solution;
  solution.tags_used = static_cast<int>(usable.size());
  size_t chosen = 0;
  if (candidates.size() > 1 &&
      candidates[1].reprojection_rms_px <= ambiguity_ratio * candidates[0].reprojection_rms_px) {
    solution.ambiguous = true;
    if (previous) {
      const double angle0 = rotation_angle_between(candidates[0].T_cam_world, *previous);
      const double angle1 = rotation_angle_between(candidates[1].T_cam_world, *previous);
      if (angle1 < angle0) chosen = 1;
    }
  }
  solution.T_cam_world = candidates[chosen].T_cam_world;
  solution.reprojection_rms_px = candidates[chosen].reprojection_rms_px;
  solution.candidates = std::move(candidates);
  return solution;
}

}  // namespace

std::optional<TagPoseSolution> solve_tag_pose(const CameraModel& camera, const std::vector<TagCorrespondence>& tags,
                                              double ambiguity_ratio, const std::optional<SE3>& previous) noexcept {
  try {
    return solve(camera, tags, ambiguity_ratio, previous);
  } catch (const std::exception& e) {
    // Degenerate corners can make OpenCV throw; for one frame that is just "no pose".
    log::debug("track: pose solve failed: {}", e.what());
    return std::nullopt;
  }
}

}  // namespace arpipe
