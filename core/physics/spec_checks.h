// Checks of physics specs and settings before anything reaches Bullet: every number finite and in
// range, sizes positive, meshes sound. Each failure is a PhysicsError naming the item and field.
#pragma once

#include <cstddef>
#include <string>

#include "core/physics/collider_spec.h"
#include "core/physics/rigid_body_spec.h"
#include "core/physics/rigid_world_settings.h"

namespace arpipe {

// "body 2 (\"ball\")", "collider 0": how messages name an item.
std::string physics_item_label(const char* what, size_t index, const std::string& name);

void check_world_settings(const RigidWorldSettings& settings);
// Everything except a mesh's content (collision_mesh.h checks that while it copies it).
void check_body_spec(const RigidBodySpec& spec, size_t index);
void check_collider_spec(const ColliderSpec& spec, size_t index);

}  // namespace arpipe
