// A simulator object's triangles in its own frame: a mesh object's glTF or builtin at its size
// (mesh_scale not applied), checked; shared by the ray tracer (scene_shader.cpp) and the scene's
// export (scene_export.h).
#pragma once

#include "capture/sim/sim_scene.h"
#include "core/scene/mesh.h"

namespace arpipe::sim {

// Throws std::invalid_argument (a bad size or scale) or AssetError naming the object.
Mesh sim_object_mesh(const SimObject& object);

}  // namespace arpipe::sim
