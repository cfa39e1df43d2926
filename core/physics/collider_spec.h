// A static collider standing for real geometry (a proxy with role "collide"): a plane, a primitive
// or a mesh, placed in the anchor (world) frame, with its surface coefficients.
#pragma once

#include <string>

#include "core/geometry/se3.h"
#include "core/physics/shape_spec.h"

namespace arpipe {

struct ColliderSpec {
  std::string name;  // for messages and reports only ("table"); may be empty
  ColliderShape shape = PlaneShape{};
  // The shape's frame in the world: the centre of a primitive, the frame of a mesh's vertices, the
  // plane's own frame (its z = 0 plane, normal +z). The identity with a plane is the ground z = 0.
  SE3 T_world_collider;
  // Combined with the body's by product (rigid_body_spec.h); 1 lets the body's values apply.
  double restitution = 1.0;  // [0, 1]
  double friction = 1.0;     // [0, 10]
  double rolling_friction = 0;  // [0, 10]
};

}  // namespace arpipe
