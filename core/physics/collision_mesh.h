// A core Mesh as the physics takes it: checked (sizes, indices, finite vertices, limits, manifold
// edges for triangle colliders), scaled, with degenerate triangles dropped and counted. No Bullet.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/physics/shape_spec.h"

namespace arpipe {

struct CollisionMesh {
  std::vector<Vec3> vertices;                     // scaled, in the shape's frame
  std::vector<std::array<uint32_t, 3>> triangles; // MeshCollision::Triangles only: non-degenerate ones
  size_t degenerate_triangles = 0;                // skipped (zero area after scaling)
};

// Throws PhysicsError naming `who` (physics_item_label), the mesh's source and the place in it.
CollisionMesh make_collision_mesh(const MeshShape& shape, const std::string& who);

}  // namespace arpipe
