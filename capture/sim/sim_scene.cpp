// SimScene helpers.
#include "capture/sim/sim_scene.h"

#include <algorithm>
#include <cmath>

namespace arpipe::sim {

int samples_per_axis(int samples_per_pixel) {
  if (samples_per_pixel < 1) return 0;
  const int root = static_cast<int>(std::lround(std::sqrt(double(samples_per_pixel))));
  return root * root == samples_per_pixel ? root : 0;
}

bool SimScene::has_virtual_objects() const {
  return std::any_of(objects.begin(), objects.end(), [](const SimObject& object) { return object.is_virtual; });
}

}  // namespace arpipe::sim
