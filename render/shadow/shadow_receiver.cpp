// The shadow catcher's ground patch (see shadow_receiver.h).
#include "render/shadow/shadow_receiver.h"

#include <algorithm>

#include "core/scene/builtin_meshes.h"

namespace arpipe {

ShadowReceiver::ShadowReceiver(int subdivisions) : subdivisions_(subdivisions) {
  object_.mesh = std::make_shared<GpuMesh>(make_plane_mesh(1.0, subdivisions));
  object_.mesh_source = "shadow catcher";
  object_.shadow_catcher = true;
  object_.base_color = std::array<float, 4>{0, 0, 0, 1};
}

const UploadedObject& ShadowReceiver::over(const ReceiverPatch& patch) {
  const double side = std::max(patch.max[0] - patch.min[0], patch.max[1] - patch.min[1]);
  object_.scale = side;
  object_.T_world_object = SE3(SE3::identity().rotation(), {0.5 * (patch.min[0] + patch.max[0]),
                                                            0.5 * (patch.min[1] + patch.max[1]), patch.height});
  object_.bounds = {{-0.5 * side, -0.5 * side, 0}, {0.5 * side, 0.5 * side, 0}};
  return object_;
}

}  // namespace arpipe
