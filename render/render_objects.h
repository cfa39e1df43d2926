// The scene's virtual objects as the render stage draws them: meshes loaded and uploaded once per
// configure, with their placement on the anchor and their base colours.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/se3.h"
#include "render/gpu_mesh.h"
#include "core/scene/mesh.h"

namespace arpipe {

struct RenderObject {
  std::string mesh_source;               // as the config names it, for messages
  std::shared_ptr<const GpuMesh> mesh;   // shared by objects that name the same mesh
  Bounds bounds;                         // in the object frame, scaled
  SE3 T_world_object;                    // placement without the scale
  double scale = 1.0;
  std::optional<std::array<float, 4>> base_color;  // set for builtin meshes (config colour); else the file's
  // The real ground under the objects (render/shadow_receiver.h): drawn as the shadow's
  // darkening, never as a surface, and it casts nothing.
  bool shadow_catcher = false;
  double specular = 0;  // weight of the environment's glossy reflection (config)
};


// Loads every render.objects entry; needs a current GL context. Each distinct mesh is read once.
// Throws ConfigError for an unknown "builtin:" name and AssetError for a missing or bad file.
std::vector<RenderObject> load_render_objects(const Config& config);

}  // namespace arpipe
