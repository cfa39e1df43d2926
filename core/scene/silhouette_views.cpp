// Where a proxy's silhouette is compared with its original's: cameras on the faces, edges and
// corners of a cube around the mesh, looking at its centre, and the comparison over those views.
#include "core/scene/silhouette_views.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/geometry/math_constants.h"

namespace arpipe {

SE3 look_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = normalized(target - eye);
  Vec3 up{0, 0, 1};
  if (norm(cross(forward, up)) < 1e-9) up = {0, 1, 0};
  const Vec3 right = normalized(cross(forward, up));
  const Vec3 down = cross(forward, right);
  const Mat3 R_cam_mesh{{{right[0], right[1], right[2]}, {down[0], down[1], down[2]}, {forward[0], forward[1], forward[2]}}};
  return SE3(R_cam_mesh, -1.0 * mat_mul(R_cam_mesh, eye));
}

double bounding_radius_m(const Bounds& box) { return 0.5 * norm(box.max - box.min); }

std::vector<SilhouetteView> cube_views_around(const Bounds& box, double distance_m) {
  const Vec3 centre = 0.5 * (box.min + box.max);
  std::vector<SilhouetteView> views;
  static constexpr const char* kAxisName[3] = {"x", "y", "z"};
  for (int a = -1; a <= 1; ++a)
    for (int b = -1; b <= 1; ++b)
      for (int c = -1; c <= 1; ++c) {
        if (a == 0 && b == 0 && c == 0) continue;
        const Vec3 direction{double(a), double(b), double(c)};
        std::string name;
        for (size_t axis = 0; axis < 3; ++axis)
          if (direction[axis] != 0) name += std::string(direction[axis] > 0 ? "+" : "-") + kAxisName[axis];
        views.push_back({name, look_at(centre + distance_m * normalized(direction), centre)});
      }
  return views;
}

std::optional<double> default_view_distance_m(const Bounds& box, const CameraModel& camera) {
  if (!camera.has_core()) return std::nullopt;
  const double focal = std::min(camera.fx(), camera.fy());
  return 4 * focal * bounding_radius_m(box) / std::min(camera.width(), camera.height());
}

CameraModel default_silhouette_camera() {
  constexpr int kWidth = 640, kHeight = 480;
  const double f = 0.5 * kWidth / std::tan(kPi / 6);  // 60 degrees across
  return CameraModel::pinhole(f, f, 0.5 * (kWidth - 1), 0.5 * (kHeight - 1), kWidth, kHeight);
}

SilhouetteComparison compare_silhouettes(const Mesh& reference, const Mesh& other, const CameraModel& camera,
                                         const std::vector<SilhouetteView>& views, int samples_per_axis) {
  const auto start = std::chrono::steady_clock::now();
  SilhouetteComparison out;
  double sum = 0;
  out.max_error_px = std::numeric_limits<double>::quiet_NaN();
  for (const SilhouetteView& view : views) {
    SilhouetteMask reference_mask(camera.width(), camera.height(), samples_per_axis);
    SilhouetteMask other_mask(camera.width(), camera.height(), samples_per_axis);
    SilhouetteViewResult result;
    result.name = view.name;
    result.skipped_triangles = draw_mesh_silhouette(reference, camera, view.T_cam_mesh, reference_mask) +
                               draw_mesh_silhouette(other, camera, view.T_cam_mesh, other_mask);
    result.error = silhouette_edge_error(reference_mask, other_mask);
    if (std::isfinite(result.error.error_px)) {
      ++out.views_measured;
      sum += result.error.error_px;
      if (!(result.error.error_px <= out.max_error_px)) {
        out.max_error_px = result.error.error_px;
        out.worst_view = view.name;
      }
    }
    out.views.push_back(std::move(result));
  }
  out.mean_error_px = out.views_measured > 0 ? sum / double(out.views_measured) : std::numeric_limits<double>::quiet_NaN();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace arpipe
