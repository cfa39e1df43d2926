// SimScene helpers.
#include "capture/sim/sim_scene.h"

#include <algorithm>

namespace arpipe::sim {

bool SimScene::has_virtual_objects() const {
  return std::any_of(objects.begin(), objects.end(), [](const SimObject& object) { return object.is_virtual; });
}

}  // namespace arpipe::sim
