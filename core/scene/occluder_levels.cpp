// Coarser occluder meshes (see occluder_levels.h).
#include "core/scene/occluder_levels.h"

#include <array>
#include <cmath>
#include <exception>

#include "core/log.h"
#include "core/scene/mesh_simplify.h"

namespace arpipe {

std::vector<OccluderLevel> make_occluder_levels(const Mesh& mesh) {
  std::vector<OccluderLevel> levels;
  if (mesh.triangle_count() < kMinOccluderLevelTriangles) return levels;
  constexpr std::array<double, 8> kErrorBounds{0.0001, 0.0002, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.03};
  size_t previous = mesh.triangle_count();
  for (double bound : kErrorBounds) {
    MeshSimplifyResult result;
    try {
      result = simplify_mesh_within_error(mesh, bound);
    } catch (const std::exception& e) {
      log::warn("proxy {}: no coarser occluder levels ({}); the full mesh is drawn", mesh.source, e.what());
      return {};
    }
    const size_t triangles = result.mesh.triangle_count();
    if (triangles == 0 || 2 * triangles > previous) continue;  // not worth a level of its own
    previous = triangles;
    levels.push_back({std::make_shared<const Mesh>(std::move(result.mesh)), result.error * result.scale_m});
  }
  return levels;
}

int coarsest_occluder_level(std::span<const double> errors_m, double focal_px, double depth_m, double tolerance_px) {
  if (!(tolerance_px > 0) || !(depth_m > 0) || !std::isfinite(depth_m)) return -1;
  int chosen = -1;
  for (size_t i = 0; i < errors_m.size(); ++i)
    if (focal_px * errors_m[i] / depth_m <= tolerance_px) chosen = static_cast<int>(i);
  return chosen;
}

}  // namespace arpipe
