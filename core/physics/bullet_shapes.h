// Internal to core/physics (only rigid_world.cpp includes it): Bullet collision shapes built from
// the checked shape specs, with the mesh data they point at and the centre of mass they imply.
#pragma once

#include <btBulletCollisionCommon.h>

#include <memory>
#include <string>

#include "core/physics/shape_spec.h"

namespace arpipe {

struct BulletShape {
  std::unique_ptr<btTriangleMesh> triangle_data;  // what a btBvhTriangleMeshShape reads; outlives it
  std::unique_ptr<btCollisionShape> shape;        // centred on the centre of mass for hulls
  Vec3 centre_of_mass{0, 0, 0};                   // in the spec's shape frame
  size_t degenerate_triangles = 0;
};

// Both throw PhysicsError naming `who` (a flat hull, a mesh that fails its checks).
BulletShape make_bullet_body_shape(const BodyShape& shape, const std::string& who);
BulletShape make_bullet_collider_shape(const ColliderShape& shape, const std::string& who);

// Triangles a mesh shape will hand to Bullet (for the world's total limit, before building it).
size_t bullet_shape_triangle_count(const BodyShape& shape);
size_t bullet_shape_triangle_count(const ColliderShape& shape);

}  // namespace arpipe
