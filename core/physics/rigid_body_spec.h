// What a config gives per virtual rigid body ([render.objects.physics]): its kind, mass, initial
// motion, surface coefficients, shape and where it starts, in the anchor (world) frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/se3.h"
#include "core/physics/shape_spec.h"

namespace arpipe {

// Static: never moves (a virtual table). Dynamic: moved by gravity and contacts. Kinematic: follows
// its pose track and pushes dynamic bodies, but nothing pushes it.
enum class BodyKind { Static, Dynamic, Kinematic };

// A kinematic body's pose at one instant (CLOCK_MONOTONIC ns). Between keys the pose moves at
// constant velocity (SE3 "centre line" interpolation); before the first and after the last it holds.
struct BodyPoseKey {
  int64_t time_ns = 0;
  SE3 T_world_body;
};

struct RigidBodySpec {
  std::string name;  // for messages and reports only ("ball"); may be empty
  BodyKind kind = BodyKind::Dynamic;
  double mass_kg = 1.0;  // dynamic bodies only; uniform density over the shape
  // Initial motion (dynamic bodies): velocity of the centre of mass and angular velocity, both in
  // the world frame.
  Vec3 linear_velocity_mps{0, 0, 0};
  Vec3 angular_velocity_radps{0, 0, 0};
  // Surface coefficients. Bullet combines the two bodies of a contact: restitution and friction by
  // their product, rolling friction as a.rolling * b.friction + b.rolling * a.friction. Colliders
  // default to restitution 1 and friction 1, so against them a body's own values apply.
  double restitution = 0.5;  // [0, 1]
  double friction = 0.5;     // [0, 10]
  double rolling_friction = 0;  // [0, 10], metres (a torque arm); 0: a ball rolls on for ever
  // Linear and angular velocity damping per second in [0, 1] (air drag stand-in); 0: none.
  double linear_damping = 0;
  double angular_damping = 0;
  BodyShape shape = SphereShape{};
  // Where the shape sits in the body's frame. The body frame is the object's (the renderer's mesh
  // frame, base on z = 0 for builtin meshes), so a builtin sphere of radius r has its shape at
  // (0, 0, r). The centre of mass is the shape's centre (a hull's volume centroid).
  SE3 T_body_shape;
  SE3 T_world_body;  // the initial pose (kinematic bodies: overridden by the track, if any)
  std::vector<BodyPoseKey> track;  // kinematic bodies only; time-ordered, strictly increasing
};

}  // namespace arpipe
