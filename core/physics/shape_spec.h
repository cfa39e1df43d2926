// The shapes a rigid body or a collider can have: primitives centred on their own frame, or a core
// Mesh (in its own frame, scaled) as a convex hull or as triangles. Plain data, checked by the world.
#pragma once

#include <memory>
#include <variant>

#include "core/geometry/vec.h"
#include "core/scene/mesh.h"

namespace arpipe {

struct SphereShape {
  double radius_m = 0.05;
};

// A box centred on its frame, axes along the frame's axes.
struct BoxShape {
  Vec3 half_extents_m{0.05, 0.05, 0.05};
};

// A cylinder centred on its frame, its axis along the frame's z (the up axis of builtin meshes).
struct CylinderShape {
  double radius_m = 0.05;
  double half_height_m = 0.05;
};

// How a mesh collides:
// ConvexHull: the convex hull of its vertices (any body kind; the only mesh form a dynamic body can
//   have). Vertices only: triangles, winding and manifoldness do not matter.
// Triangles: the triangles themselves (concave; static colliders, static and kinematic bodies).
//   Degenerate triangles are skipped and counted; an edge shared by more than two triangles
//   (non-manifold, positions welded by value) is an error.
enum class MeshCollision { ConvexHull, Triangles };

// A core Mesh in the shape's frame, each vertex multiplied component-wise by scale (the scale is
// baked into the physics copy; the Mesh is not kept after the shape is built).
struct MeshShape {
  std::shared_ptr<const Mesh> mesh;
  Vec3 scale{1, 1, 1};
  MeshCollision collision = MeshCollision::ConvexHull;
};

// The plane z = 0 of the collider's frame, solid below it (normal along the frame's +z): the
// ground, a wall, a table top without edges.
struct PlaneShape {};

using BodyShape = std::variant<SphereShape, BoxShape, CylinderShape, MeshShape>;
using ColliderShape = std::variant<PlaneShape, SphereShape, BoxShape, CylinderShape, MeshShape>;

}  // namespace arpipe
