// A triangle mesh in an object's own frame (metres, z up): what the loaders produce and the GPU
// upload consumes. Parts share the vertex arrays and differ in base colour.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

struct MeshPart {
  uint32_t first_index = 0;  // into Mesh::indices
  uint32_t index_count = 0;
  std::array<float, 4> base_color{1, 1, 1, 1};  // linear RGBA, not premultiplied
};

struct Bounds {
  Vec3 min{0, 0, 0};
  Vec3 max{0, 0, 0};
};

// The box's 8 corners; bit 0 of the index picks max x, bit 1 max y, bit 2 max z.
inline std::array<Vec3, 8> box_corners(const Bounds& box) {
  std::array<Vec3, 8> out{};
  for (size_t i = 0; i < 8; ++i)
    out[i] = {(i & 1) ? box.max[0] : box.min[0], (i & 2) ? box.max[1] : box.min[1], (i & 4) ? box.max[2] : box.min[2]};
  return out;
}

struct Mesh {
  std::vector<float> positions;  // x, y, z per vertex
  std::vector<float> normals;    // unit, x, y, z per vertex
  std::vector<uint32_t> indices; // three per triangle, counter-clockwise seen from outside
  std::vector<MeshPart> parts;
  // Where the mesh came from (the glTF file's path, "builtin:cube", ...), for messages about it;
  // not part of its content (the PRT cache key ignores it). Empty when unknown.
  std::string source;

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
  Bounds bounds() const;  // axis-aligned, of all vertices; zero box for an empty mesh
  // Sets every part's base colour (builtin meshes take theirs from the config).
  void set_base_color(const std::array<float, 4>& rgba);
};

}  // namespace arpipe
