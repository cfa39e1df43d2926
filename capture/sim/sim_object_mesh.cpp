// A simulator mesh object's triangles, checked.
#include "capture/sim/sim_object_mesh.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"

namespace arpipe::sim {
namespace {

void check_mesh_object(bool ok, const SimObject& object, const std::string& what) {
  if (!ok) throw std::invalid_argument(fmt::format("object \"{}\": {}", object.name, what));
}

}  // namespace

Mesh sim_object_mesh(const SimObject& object) {
  check_mesh_object(object.mesh_scale > 0, object, fmt::format("mesh_scale must be positive, got {}", object.mesh_scale));
  try {
    if (object.mesh_builtin.empty()) return load_gltf_mesh(object.mesh_path);
    if (object.mesh_size_m) {
      const Vec3& size = *object.mesh_size_m;
      const bool plane = object.mesh_builtin == "builtin:plane";
      check_mesh_object(builtin_mesh_is_sized(object.mesh_builtin), object,
                   fmt::format("\"{}\" has a fixed size; a size applies to \"builtin:box\", \"builtin:cylinder\" and "
                               "\"builtin:plane\"",
                               object.mesh_builtin));
      check_mesh_object(std::isfinite(size[0]) && std::isfinite(size[1]) && std::isfinite(size[2]) && size[0] > 0 &&
                       size[1] > 0 && (plane ? size[2] >= 0 : size[2] > 0),
                   object,
                   fmt::format("a mesh size must be finite and positive, got [{}, {}, {}] m", size[0], size[1], size[2]));
    }
    auto builtin = object.mesh_size_m ? make_builtin_mesh(object.mesh_builtin, *object.mesh_size_m)
                                      : make_builtin_mesh(object.mesh_builtin);
    if (!builtin)
      throw AssetError(fmt::format("unknown builtin mesh \"{}\" (expected {})", object.mesh_builtin, kBuiltinMeshNames));
    return std::move(*builtin);
  } catch (const AssetError& e) {
    throw AssetError(fmt::format("object \"{}\": {}", object.name, e.what()));
  }
}

}  // namespace arpipe::sim
