// Kinematic tracks: a binary search for the keys around t, then SE3's interpolation of T_world_body,
// which moves the body origin straight in the world.
#include "core/physics/kinematic_track.h"

#include <algorithm>

#include "core/geometry/se3_interpolation.h"

namespace arpipe {

SE3 pose_on_track(const std::vector<BodyPoseKey>& track, int64_t t_ns, const SE3& fallback) {
  if (track.empty()) return fallback;
  if (t_ns <= track.front().time_ns) return track.front().T_world_body;
  if (t_ns >= track.back().time_ns) return track.back().T_world_body;
  const auto after = std::upper_bound(track.begin(), track.end(), t_ns,
                                      [](int64_t t, const BodyPoseKey& key) { return t < key.time_ns; });
  const BodyPoseKey& b = *after;
  const BodyPoseKey& a = *(after - 1);
  return a.T_world_body.interpolate(b.T_world_body, time_fraction(a.time_ns, b.time_ns, t_ns));
}

}  // namespace arpipe
