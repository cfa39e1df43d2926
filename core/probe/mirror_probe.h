// Beyond the seed: a mirror ball turned into a world-frame environment map (every pixel's true view
// ray reflected at its hit point), its dominant lights found by peak finding, the rest as SH ambient.
#pragma once

#include <vector>

#include "core/light/light_estimate.h"
#include "core/light/linear_patch.h"
#include "core/probe/probe_sphere.h"

namespace arpipe {

// Equirectangular, world frame: column i covers azimuth phi in [2 pi i / W, 2 pi (i+1) / W) about
// +z from +x; row j covers polar angle theta (from +z, up) in [pi j / H, pi (j+1) / H).
struct EnvironmentMap {
  int width = 64, height = 32;
  std::vector<Vec3> radiance;     // scene-linear radiance (already divided by the reflectance)
  std::vector<double> weight;     // solid angle of reflected directions that fell in the cell
  std::vector<uint8_t> seen;      // 1: measured; 0: filled (gaps, the blind cone behind the ball)
  std::vector<uint8_t> light;     // 1: belongs to a detected light (replaced in the ambient)
  Vec3 direction(int i, int j) const;
  double cell_solid_angle(int j) const;
  int cell_of(const Vec3& dir) const;  // index j * width + i
};

struct MirrorLight {
  DirectionalLight light;   // direction from the ball's centre (see light_distance_m)
  Vec3 direction_from_point{0, 0, 1};   // unit, as seen from the reflecting point (no parallax fix)
  Vec3 reflection_point_world{0, 0, 0}; // where on the ball the light is reflected
  bool clipped = false;      // some of its pixels are clipped: the irradiance is a lower bound
  double clipped_fraction = 0;
  double peak_contrast = 0;  // its peak radiance over the median radiance of the map
  int pixels = 0;
};

struct MirrorProbeOptions {
  int max_lights = 1;
  int map_width = 64, map_height = 32;
  double min_peak_contrast = 8;  // a light's peak must be this many times the map's median
  double light_threshold = 0.1;  // a pixel belongs to the light from this fraction of its peak up
  // A mirror ball sees a light from the point that reflects it, not from its centre: for a light at
  // distance D the two directions differ by up to r sin(angle/2) / D (2.4 degrees for a 4 cm ball
  // and a lamp at 0.5 m). Given D (> r) the direction is corrected to the centre's; 0: the light
  // is taken as infinitely far (the environment map's own convention).
  double light_distance_m = 0;
};

struct MirrorProbeResult {
  std::vector<MirrorLight> lights;  // strongest first
  ShRgb9 ambient_sh{};              // radiance SH of the map with the lights taken out
  EnvironmentMap map;
  double clipped_fraction = 0;      // of the analysed pixels
  double seen_fraction = 0;         // of the map's solid angle measured directly
  int pixels = 0;
};

// Needs region and patch of the same frame (the patch covering region.rect).
MirrorProbeResult analyse_mirror_probe(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                                       const MirrorProbeOptions& options);

}  // namespace arpipe
