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

bool SimScene::has_animated_objects() const {
  return std::any_of(objects.begin(), objects.end(), [](const SimObject& object) { return !object.keyframes.empty(); });
}

SE3 object_pose_at(const SimObject& object, double t_s) {
  const std::vector<SimPoseKey>& keys = object.keyframes;
  if (keys.empty()) return object.T_world_object;
  if (!(t_s > keys.front().time_s)) return keys.front().T_world_object;  // NaN too
  if (t_s >= keys.back().time_s) return keys.back().T_world_object;
  // The first key after t: t lies in [before.time_s, after.time_s).
  const auto after = std::upper_bound(keys.begin(), keys.end(), t_s,
                                      [](double t, const SimPoseKey& key) { return t < key.time_s; });
  const SimPoseKey& before = *(after - 1);
  if (t_s == before.time_s) return before.T_world_object;
  const double s = (t_s - before.time_s) / (after->time_s - before.time_s);
  return before.T_world_object.interpolate(after->T_world_object, s);
}

SimScene scene_at_time(const SimScene& scene, double t_s) {
  SimScene still = scene;
  for (SimObject& object : still.objects) {
    object.T_world_object = object_pose_at(object, t_s);
    object.keyframes.clear();
  }
  return still;
}

}  // namespace arpipe::sim
