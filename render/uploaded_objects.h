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
#include "render/gl/gpu_mesh.h"
#include "core/scene/mesh.h"

namespace arpipe {

struct UploadedObject {
  std::string mesh_source;               // as the config names it, for messages
  std::shared_ptr<const GpuMesh> mesh;   // shared by objects that name the same mesh
  Bounds bounds;                         // in the object frame, scaled
  SE3 T_world_object;                    // placement without the scale
  double scale = 1.0;
  std::optional<std::array<float, 4>> base_color;  // set for builtin meshes (config colour); else the file's
  // The real ground under the objects (render/shadow/shadow_receiver.h): drawn as the shadow's
  // darkening, never as a surface, and it casts nothing.
  bool shadow_catcher = false;
  double specular = 0;  // weight of the environment's glossy reflection (config)
};


// The meshes of render.objects read (and their PRT transfer baked or taken from the cache) on the
// CPU, without GL, so a reload can do it away from the processing thread. Each distinct mesh and
// prt mode is loaded once. Throws ConfigError for an unknown "builtin:" name and AssetError for a
// missing or bad file or a failed bake, naming the config key (render.objects[i].mesh) and the file.
struct LoadedMeshes {
  struct Entry {
    Mesh mesh;
    std::vector<float> transfer;  // 9 coefficients per vertex, or empty without PRT
  };
  std::vector<Entry> meshes;
  std::vector<size_t> mesh_of_object;  // per render.objects entry: its index in meshes
};
LoadedMeshes load_object_meshes(const Config& config);

// Uploads what load_object_meshes made of this same config and places the objects; needs a current
// GL context.
std::vector<UploadedObject> upload_objects(const Config& config, const LoadedMeshes& loaded);

// Both of the above, on the calling thread.
std::vector<UploadedObject> load_and_upload_objects(const Config& config);

}  // namespace arpipe
