// The virtual shadow against the simulator's ray-traced truth, shared by the shadow tests and
// `arpipe bench shadows`: a scene's virtual ball drawn by the render and composite stages over a
// white camera frame (each output pixel then decodes to the shadow ratio the catcher applied),
// against the ratio of the simulator's radiance with and without the ball (sim/shadow_factor.h).
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include "capture/sim/shadow_factor.h"
#include "core/config/config.h"
#include "core/geometry/se3.h"

namespace arpipe::bench {

// What a simulated scene's header comment says about its virtual ball, its light and the camera's
// first keyframe. The light becomes a config's fixed light: the direct light as seen from the
// ball, the rest (fill light, sky) as ambient; only their ratio matters to the catcher.
struct ShadowScene {
  std::string file;      // in configs/sim
  Vec3 ball_centre;
  double ball_radius;
  Vec3 towards_light;    // from the ball
  Vec3 light_position;   // a lamp; zero: infinitely far
  Vec3 direct;           // irradiance on a surface facing the light
  Vec3 ambient;          // irradiance on the ground from everything else
  double light_diameter_rad;
  SE3 camera;
  std::array<double, 4> ground_xy;  // x0, x1, y0, y1: the ground around the ball and its shadow
};

ShadowScene probe_indoor_shadow_scene();
ShadowScene sun_outdoor_shadow_scene();

// method: a render.shadows.method, optionally with the PCF kernel after a colon ("pcf:8") and
// "+sky" for render.shadows.sky_occlusion ("pcss+sky").
Config shadow_config(const ShadowScene& scene, const std::string& method, int map_size = 1024);

struct ShadowTruth {
  sim::ShadowFactorImage image;
  sim::PixelRegion region;
};
// Ray traced once per scene file and kept (64 light samples: the penumbra's noise is about 0.06
// at worst per pixel, far less on average).
const ShadowTruth& shadow_truth(const std::filesystem::path& scenes_dir, const ShadowScene& scene);

struct ShadowComparison {
  double mae = 0;       // over the shadow: pixels where either side is darkened by more than 2 %
  int pixels = 0;
  double truth_min = 1;
  double shadow_ms = 0;  // the shadow map pass of the frame (0 when reused)
  double render_ms = 0;  // the render stage in all, shadow map included
};
// Draws `frames` frames (the light turned by 0.1 degree every other frame, so that each frame
// draws its map again) and compares the last with the truth; times are medians.
ShadowComparison compare_shadow(const std::filesystem::path& scenes_dir, const ShadowScene& scene,
                                const std::string& method, int map_size = 1024, int frames = 1);

}  // namespace arpipe::bench
