// Test helpers for the track tests: camera models, random camera poses looking at the anchor, and
// tag corners projected exactly through the camera model (the ground truth the solver must recover).
#include "synthetic_tag_views.h"

#include <cmath>
#include <stdexcept>

#include "core/track/bundle_tag_geometry.h"

namespace arpipe::test {

CameraModel pinhole_640x480() { return CameraModel::pinhole(500, 505, 319.5, 239.5, 640, 480); }

CameraModel opencv8_640x480() {
  // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6 (OpenCV's order, as mrcal stores it).
  return CameraModel("LENSMODEL_OPENCV8",
                     {480, 482, 322.1, 236.7, -0.28, 0.09, 0.0012, -0.0008, -0.012, 0.02, -0.005, 0.003}, 640, 480);
}

SE3 look_at(const Vec3& target, double distance, double tilt, double azimuth, double roll) {
  const Vec3 offset{std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth), std::cos(tilt)};
  const Vec3 centre = target + distance * offset;
  const Vec3 forward = normalized(target - centre);
  // Any helper vector not parallel to the viewing direction fixes the zero of the roll angle.
  const Vec3 helper = std::abs(forward[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 x0 = normalized(cross(helper, forward));
  const Vec3 y0 = cross(forward, x0);
  const Vec3 x = std::cos(roll) * x0 + std::sin(roll) * y0;
  const Vec3 y = cross(forward, x);
  const Mat3 R_world_cam{{{x[0], y[0], forward[0]}, {x[1], y[1], forward[1]}, {x[2], y[2], forward[2]}}};
  return SE3(R_world_cam, centre).inverse();
}

std::optional<std::vector<TagCorrespondence>> project_bundle(const CameraModel& camera, const SE3& T_cam_world,
                                                             const std::vector<BundleTag>& bundle, double sigma_px,
                                                             std::mt19937_64& rng) {
  constexpr double kMargin = 4;
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<TagCorrespondence> tags;
  for (const BundleTag& tag : bundle) {
    TagCorrespondence correspondence;
    correspondence.world = bundle_tag_world_corners(tag);
    for (size_t c = 0; c < 4; ++c) {
      const auto pixel = camera.project(T_cam_world * correspondence.world[c]);
      if (!pixel || (*pixel)[0] < kMargin || (*pixel)[1] < kMargin || (*pixel)[0] > camera.width() - 1 - kMargin ||
          (*pixel)[1] > camera.height() - 1 - kMargin) {
        return std::nullopt;
      }
      correspondence.pixels[c] = *pixel;
      if (sigma_px > 0) {
        correspondence.pixels[c][0] += sigma_px * noise(rng);
        correspondence.pixels[c][1] += sigma_px * noise(rng);
      }
    }
    tags.push_back(correspondence);
  }
  return tags;
}

SE3 random_view(const CameraModel& camera, const std::vector<BundleTag>& bundle, const ViewRange& range,
                std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr double kPi = 3.14159265358979323846;
  for (int attempt = 0; attempt < 10000; ++attempt) {
    const double distance = range.min_distance + (range.max_distance - range.min_distance) * unit(rng);
    const double tilt = range.min_tilt + (range.max_tilt - range.min_tilt) * unit(rng);
    const Vec3 target{range.target_jitter * (2 * unit(rng) - 1), range.target_jitter * (2 * unit(rng) - 1), 0};
    const SE3 pose = look_at(target, distance, tilt, 2 * kPi * unit(rng), 2 * kPi * unit(rng));
    std::mt19937_64 unused(0);
    if (project_bundle(camera, pose, bundle, 0, unused)) return pose;
  }
  throw std::logic_error("random_view: no view in range shows the whole bundle");
}

std::vector<BundleTag> four_tag_bundle() {
  constexpr double kDeg = 3.14159265358979323846 / 180;
  return {BundleTag{3, 0.08, {-0.06, -0.06, 0}, 0},
          BundleTag{7, 0.06, {0.06, -0.06, 0}, 90 * kDeg},
          BundleTag{11, 0.08, {0.06, 0.07, 0}, 180 * kDeg},
          BundleTag{12, 0.05, {-0.065, 0.065, 0}, 30 * kDeg}};
}

}  // namespace arpipe::test
