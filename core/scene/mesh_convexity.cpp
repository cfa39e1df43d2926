// Whether a mesh bounds a convex solid (see mesh_convexity.h).
#include "core/scene/mesh_convexity.h"

#include <cmath>

#include "core/scene/asset_error.h"
#include "core/scene/mesh_weld.h"

namespace arpipe {
bool is_closed_convex(const Mesh& mesh) {
  const Bounds box = mesh.bounds();
  const double diagonal = norm(box.max - box.min);
  if (!(diagonal > 0) || !std::isfinite(diagonal)) return false;
  WeldedMesh welded;
  try {
    welded = weld_by_position(mesh, 1e-6 * diagonal);
  } catch (const AssetError&) {
    return false;  // not a mesh: the loaders have said so already
  }
  if (welded.triangle_count() < 4 || count_unpaired_edges(welded) != 0) return false;
  if (double(welded.triangle_count()) * double(welded.vertex_count()) > kMaxConvexityWork) return false;
  const double tolerance = 1e-6 * diagonal;
  for (size_t t = 0; t < welded.triangle_count(); ++t) {
    const Vec3 a = welded.position_of(welded.indices[3 * t]);
    const Vec3 b = welded.position_of(welded.indices[3 * t + 1]);
    const Vec3 c = welded.position_of(welded.indices[3 * t + 2]);
    const Vec3 n = cross(b - a, c - a);
    const double length = norm(n);
    if (!(length > 0)) continue;  // a sliver has no plane; its neighbours' planes bound it
    const Vec3 outward = (1.0 / length) * n;
    for (size_t v = 0; v < welded.vertex_count(); ++v)
      if (dot(outward, welded.position_of(uint32_t(v)) - a) > tolerance) return false;
  }
  return true;
}

}  // namespace arpipe
