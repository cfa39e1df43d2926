// A mesh's triangles over shared positions: vertices that differ only in their normals (the seams
// of flat or split normals) become one, so that simplifiers and closure checks see one surface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/scene/mesh.h"

namespace arpipe {

struct WeldedMesh {
  std::vector<float> positions;   // x, y, z per distinct position
  std::vector<uint32_t> indices;  // three per triangle, the input's winding
  std::vector<uint32_t> triangle_part;  // per triangle: its Mesh::parts entry (parts.size(): in none)

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
  Vec3 position_of(uint32_t v) const {
    return {positions[3 * size_t{v}], positions[3 * size_t{v} + 1], positions[3 * size_t{v} + 2]};
  }
};

// Positions closer than about `tolerance_m` become one vertex (they are snapped to a grid of that
// step and compared there, with meshopt_generateVertexRemap: two positions straddling a grid line
// may stay apart, which leaves a crack a simplifier keeps, never a wrong surface). The welded
// vertex keeps one of the input positions. Triangles that lose a corner to the weld (two corners
// now the same vertex) are dropped. tolerance_m <= 0 welds equal positions only.
// Throws AssetError naming Mesh::source and the place when the mesh is not one: no triangles, an
// index count not a multiple of 3, an index past the last vertex, a position not finite, a part
// outside the index list.
WeldedMesh weld_by_position(const Mesh& mesh, double tolerance_m);

// Triangle edges of the welded mesh that are not one of a pair (an edge a -> b in exactly one
// triangle and b -> a in exactly one other): 0 for a closed, consistently wound 2-manifold surface.
// A border edge counts 1, an edge that three triangles share 3.
size_t count_unpaired_edges(const WeldedMesh& mesh);

}  // namespace arpipe
