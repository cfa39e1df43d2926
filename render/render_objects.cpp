// The scene's virtual objects as the render stage draws them: meshes loaded and uploaded once per
// configure, with their placement on the anchor and their base colours.
#include "render/render_objects.h"

#include <fmt/format.h>

#include <cmath>
#include <map>

#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"

namespace arpipe {
namespace {

Mesh load_mesh(const Config& config, size_t object_index, const std::string& source) {
  if (is_builtin_mesh_source(source)) {
    if (auto mesh = make_builtin_mesh(source)) return std::move(*mesh);
    throw ConfigError(fmt::format("{}: render.objects[{}].mesh: unknown builtin mesh \"{}\" (expected "
                                  "{} or a glTF 2.0 file)",
                                  config.file.empty() ? std::string("config") : config.file.string(), object_index,
                                  source, kBuiltinMeshNames));
  }
  return load_gltf_mesh(source);  // relative to the working directory, like every path in a config
}

Bounds scaled(const Bounds& box, double scale) {
  Bounds out;
  for (size_t axis = 0; axis < 3; ++axis) {
    const double a = box.min[axis] * scale, b = box.max[axis] * scale;
    out.min[axis] = std::min(a, b);
    out.max[axis] = std::max(a, b);
  }
  return out;
}

}  // namespace

std::vector<RenderObject> load_render_objects(const Config& config) {
  struct Loaded {
    std::shared_ptr<const GpuMesh> gpu;
    Bounds bounds;
  };
  std::map<std::string, Loaded> loaded;
  std::vector<RenderObject> objects;
  for (size_t i = 0; i < config.render.objects.size(); ++i) {
    const SceneObject& object = config.render.objects[i];
    auto found = loaded.find(object.mesh);
    if (found == loaded.end()) {
      const Mesh mesh = load_mesh(config, i, object.mesh);
      found = loaded.emplace(object.mesh, Loaded{std::make_shared<const GpuMesh>(mesh), mesh.bounds()}).first;
    }
    RenderObject out;
    out.mesh_source = object.mesh;
    out.mesh = found->second.gpu;
    out.scale = object.scale;
    out.bounds = scaled(found->second.bounds, object.scale);
    out.T_world_object = SE3::from_rt({0, 0, object.yaw_rad}, object.position_m);
    if (is_builtin_mesh_source(object.mesh))
      out.base_color = std::array<float, 4>{static_cast<float>(object.color[0]), static_cast<float>(object.color[1]),
                                            static_cast<float>(object.color[2]), 1.0f};
    objects.push_back(std::move(out));
  }
  return objects;
}

}  // namespace arpipe
