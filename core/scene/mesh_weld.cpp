// A mesh's triangles over shared positions: vertices that differ only in their normals (the seams
// of flat or split normals) become one, so that simplifiers and closure checks see one surface.
#include "core/scene/mesh_weld.h"

#include <fmt/format.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

std::string weld_mesh_name(const Mesh& mesh) { return mesh.source.empty() ? std::string("the mesh") : mesh.source; }

void check_weldable(const Mesh& mesh) {
  const std::string name = weld_mesh_name(mesh);
  if (mesh.positions.size() % 3 != 0)
    throw AssetError(fmt::format("{}: {} position floats, not a multiple of 3", name, mesh.positions.size()));
  if (mesh.indices.size() % 3 != 0)
    throw AssetError(fmt::format("{}: {} indices, not a multiple of 3", name, mesh.indices.size()));
  if (mesh.indices.empty()) throw AssetError(fmt::format("{}: no triangles", name));
  const size_t vertices = mesh.vertex_count();
  if (vertices > UINT32_MAX) throw AssetError(fmt::format("{}: {} vertices, more than 32-bit indices reach", name, vertices));
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      throw AssetError(fmt::format("{}: vertex {} has a coordinate that is not a finite number ({})", name, i / 3,
                                   mesh.positions[i]));
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= vertices)
      throw AssetError(fmt::format("{}: index {} (triangle {}) is {}, past the last vertex ({} vertices)", name, i,
                                   i / 3, mesh.indices[i], vertices));
  for (size_t p = 0; p < mesh.parts.size(); ++p) {
    const MeshPart& part = mesh.parts[p];
    if (part.first_index % 3 != 0 || part.index_count % 3 != 0 ||
        uint64_t{part.first_index} + part.index_count > mesh.indices.size())
      throw AssetError(fmt::format("{}: part {} (indices {} + {}) is not whole triangles of the {} indices", name, p,
                                   part.first_index, part.index_count, mesh.indices.size()));
  }
}

// Per vertex, the integers that make equal keys for positions within about one step: the position
// relative to the box's minimum in steps, rounded. The step is at least 2^-50 of the box (the
// quotients stay exact in a double and inside int64).
std::vector<int64_t> weld_grid_keys(const Mesh& mesh, double step) {
  const Bounds box = mesh.bounds();
  double extent = 0;
  for (size_t axis = 0; axis < 3; ++axis) extent = std::max(extent, box.max[axis] - box.min[axis]);
  step = std::max(step, std::ldexp(extent, -50));
  std::vector<int64_t> keys(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const double offset = double(mesh.positions[i]) - box.min[i % 3];
    keys[i] = step > 0 ? std::llround(offset / step) : 0;
  }
  return keys;
}

}  // namespace

WeldedMesh weld_by_position(const Mesh& mesh, double tolerance_m) {
  check_weldable(mesh);
  const size_t vertex_count = mesh.vertex_count();
  std::vector<unsigned int> remap(vertex_count);
  size_t unique = 0;
  if (tolerance_m > 0) {
    const std::vector<int64_t> keys = weld_grid_keys(mesh, tolerance_m);
    unique = meshopt_generateVertexRemap(remap.data(), mesh.indices.data(), mesh.indices.size(), keys.data(),
                                         vertex_count, 3 * sizeof(int64_t));
  } else {
    std::vector<float> exact = mesh.positions;
    for (float& v : exact) v += 0.0f;  // -0 becomes +0: the same position, other bits
    unique = meshopt_generateVertexRemap(remap.data(), mesh.indices.data(), mesh.indices.size(), exact.data(),
                                         vertex_count, 3 * sizeof(float));
  }

  WeldedMesh out;
  out.positions.resize(3 * unique);
  meshopt_remapVertexBuffer(out.positions.data(), mesh.positions.data(), vertex_count, 3 * sizeof(float), remap.data());

  std::vector<uint32_t> part_of_triangle(mesh.triangle_count(), static_cast<uint32_t>(mesh.parts.size()));
  for (size_t p = 0; p < mesh.parts.size(); ++p) {
    const MeshPart& part = mesh.parts[p];
    for (size_t t = part.first_index / 3; t < (part.first_index + part.index_count) / 3; ++t)
      part_of_triangle[t] = static_cast<uint32_t>(p);
  }
  out.indices.reserve(mesh.indices.size());
  out.triangle_part.reserve(mesh.triangle_count());
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t a = remap[mesh.indices[3 * t]], b = remap[mesh.indices[3 * t + 1]], c = remap[mesh.indices[3 * t + 2]];
    if (a == b || b == c || c == a) continue;
    out.indices.insert(out.indices.end(), {a, b, c});
    out.triangle_part.push_back(part_of_triangle[t]);
  }
  return out;
}

size_t count_unpaired_edges(const WeldedMesh& mesh) {
  // Per undirected edge (low, high): how often it runs low -> high and high -> low.
  std::unordered_map<uint64_t, std::array<uint32_t, 2>> runs;
  runs.reserve(mesh.indices.size());
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t from = mesh.indices[t + k], to = mesh.indices[t + (k + 1) % 3];
      const uint64_t key = uint64_t{std::min(from, to)} << 32 | std::max(from, to);
      ++runs[key][from < to ? 0 : 1];
    }
  size_t unpaired = 0;
  for (const auto& [key, count] : runs)
    unpaired += count[0] == 1 && count[1] == 1 ? 0 : count[0] + count[1];
  return unpaired;
}

}  // namespace arpipe
