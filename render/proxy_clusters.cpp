// Proxy meshes cut into culling clusters (see proxy_clusters.h).
#include "render/proxy_clusters.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace arpipe {
namespace {

// Spreads the low 10 bits of v two zeros apart (for a 30-bit 3D Morton code).
uint32_t spread_bits(uint32_t v) {
  v &= 0x3ff;
  v = (v | (v << 16)) & 0x030000ff;
  v = (v | (v << 8)) & 0x0300f00f;
  v = (v | (v << 4)) & 0x030c30c3;
  v = (v | (v << 2)) & 0x09249249;
  return v;
}

Vec3 vertex_at(const Mesh& mesh, uint32_t i) {
  return {mesh.positions[3 * size_t(i)], mesh.positions[3 * size_t(i) + 1], mesh.positions[3 * size_t(i) + 2]};
}

}  // namespace

ClusteredMesh cluster_for_culling(const Mesh& mesh, size_t triangles_per_cluster) {
  ClusteredMesh out;
  out.mesh = mesh;
  const size_t triangles = mesh.triangle_count();
  triangles_per_cluster = std::max<size_t>(triangles_per_cluster, 1);
  if (triangles <= 2 * triangles_per_cluster) return out;
  const Bounds box = mesh.bounds();
  std::vector<uint32_t> code(triangles);
  for (size_t t = 0; t < triangles; ++t) {
    const Vec3 c = (1.0 / 3.0) * (vertex_at(mesh, mesh.indices[3 * t]) + vertex_at(mesh, mesh.indices[3 * t + 1]) +
                                  vertex_at(mesh, mesh.indices[3 * t + 2]));
    uint32_t key = 0;
    for (size_t axis = 0; axis < 3; ++axis) {
      const double span = box.max[axis] - box.min[axis];
      const double f = span > 0 ? (c[axis] - box.min[axis]) / span : 0.0;
      key |= spread_bits(static_cast<uint32_t>(std::clamp(f, 0.0, 1.0) * 1023.0)) << axis;
    }
    code[t] = key;
  }
  std::vector<size_t> order(triangles);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return code[a] < code[b]; });
  out.mesh.indices.clear();
  out.mesh.indices.reserve(mesh.indices.size());
  out.mesh.parts.clear();
  const std::array<float, 4> colour = mesh.parts.empty() ? std::array<float, 4>{1, 1, 1, 1} : mesh.parts.front().base_color;
  for (size_t first = 0; first < triangles; first += triangles_per_cluster) {
    const size_t last = std::min(triangles, first + triangles_per_cluster);
    Bounds bounds{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t k = first; k < last; ++k)
      for (int corner = 0; corner < 3; ++corner) {
        const uint32_t index = mesh.indices[3 * order[k] + size_t(corner)];
        out.mesh.indices.push_back(index);
        const Vec3 p = vertex_at(mesh, index);
        for (size_t axis = 0; axis < 3; ++axis) {
          bounds.min[axis] = std::min(bounds.min[axis], p[axis]);
          bounds.max[axis] = std::max(bounds.max[axis], p[axis]);
        }
      }
    out.mesh.parts.push_back(MeshPart{static_cast<uint32_t>(3 * first), static_cast<uint32_t>(3 * (last - first)), colour});
    out.bounds.push_back(bounds);
  }
  return out;
}

}  // namespace arpipe
