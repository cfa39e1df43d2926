// A triangle mesh in an object's own frame (metres, z up): what the loaders produce and the GPU
// upload consumes. Parts share the vertex arrays and differ in base colour.
#include "core/scene/mesh.h"

#include <algorithm>

namespace arpipe {

Bounds Mesh::bounds() const {
  Bounds box;
  if (positions.empty()) return box;
  for (int axis = 0; axis < 3; ++axis) box.min[axis] = box.max[axis] = positions[static_cast<size_t>(axis)];
  for (size_t i = 0; i < positions.size(); i += 3)
    for (size_t axis = 0; axis < 3; ++axis) {
      box.min[axis] = std::min(box.min[axis], static_cast<double>(positions[i + axis]));
      box.max[axis] = std::max(box.max[axis], static_cast<double>(positions[i + axis]));
    }
  return box;
}

void Mesh::set_base_color(const std::array<float, 4>& rgba) {
  for (MeshPart& part : parts) part.base_color = rgba;
}

}  // namespace arpipe
