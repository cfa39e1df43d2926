// Image motion of reference points over their rows' exposure windows.
#include "core/motion/image_motion.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace arpipe {

double max_image_motion_px(const ShutterMotion& motion, const CameraModel& camera, const std::vector<Vec3>& world_points,
                           int steps) {
  if (!motion.valid()) return 0;
  steps = std::max(steps, 1);
  double longest = 0;
  for (const Vec3& point : world_points) {
    const Vec3 at_mid = motion.T_cam_world_mid * point;
    if (at_mid[2] <= 0) continue;
    const auto pixel = camera.project(at_mid);
    if (!pixel) continue;
    const int64_t row_start = motion.timing.row_start_ns((*pixel)[1]);
    double length = 0;
    std::optional<Vec2> previous;
    for (int i = 0; i <= steps; ++i) {
      const int64_t t = row_start + std::llround(double(motion.timing.exposure_ns) * i / steps);
      const Vec3 p = motion.T_cam_world_at(t) * point;
      const auto here = p[2] > 0 ? camera.project(p) : std::nullopt;
      if (!here) {  // leaves the model's domain during the exposure: measure what was seen
        previous.reset();
        continue;
      }
      if (previous) length += norm(*here - *previous);
      previous = here;
    }
    longest = std::max(longest, length);
  }
  return longest;
}

}  // namespace arpipe
