// The ray-traced truth for virtual shadows on real surfaces: per pixel, by how much the scene's
// virtual objects darken the real surface seen there (radiance with them over radiance without),
// the number a differential-rendering shadow catcher should reproduce.
#pragma once

#include <cstdint>
#include <vector>

#include "capture/sim/sim_scene.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"

namespace arpipe::sim {

struct ShadowFactorImage {
  int width = 0;
  int height = 0;
  std::vector<float> ratio;    // luminance ratio (Rec. 709 weights), 1 = not darkened
  std::vector<uint8_t> valid;  // 0 where the pixel sees a virtual object, nothing, or a black surface
  float at(int x, int y) const { return ratio[size_t(y) * size_t(width) + size_t(x)]; }
  bool valid_at(int x, int y) const { return valid[size_t(y) * size_t(width) + size_t(x)] != 0; }
};

// Pixels [x0, x1) x [y0, y1); the rest of the image stays invalid.
struct PixelRegion {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// Through each pixel centre of a still camera (T_cam_world), `samples` light samples with and
// without the virtual objects, drawn from the same random numbers, so that only the occlusion
// differs between the two. threads: 0 = all cores.
ShadowFactorImage render_shadow_factor(const SimScene& scene, const CameraModel& camera, const SE3& T_cam_world,
                                       int samples, const PixelRegion& region, int threads = 0);

}  // namespace arpipe::sim
