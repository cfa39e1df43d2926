// What the light stage knows about one frame's light: directional lights and the ambient light
// around them in the world (anchor) frame, in exposure-normalised units, with how sure it is.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/vec.h"
#include "core/sh/sh_basis.h"  // ShRgb9

namespace arpipe {

// Units ("scene-linear"): a camera pixel's linear value (after the camera response is undone,
// 1.0 = full scale) divided by exposure time in seconds and by the total gain. A surface of
// radiance L in these units shows as the linear pixel value L * exposure_s * gain, so an estimate
// keeps its meaning when auto-exposure changes; the renderer multiplies back by the frame's own
// exposure and gain. Irradiance is radiance times solid angle (a Lambertian surface of albedo rho
// under irradiance E has radiance rho * E / pi).
struct DirectionalLight {
  Vec3 direction_world{0, 0, 1};     // unit, from the scene towards the light
  Vec3 irradiance{0, 0, 0};          // RGB, on a surface facing the light
  double angular_diameter_rad = 0;   // apparent size of the source (penumbra width); 0 = a point
  // A lamp at a known place rather than infinitely far: shadows fan out from it (a perspective
  // shadow map). direction_world then points at it from the world origin.
  bool local = false;
  Vec3 position_world{0, 0, 0};
};


enum class LightState {
  Estimated,   // measured on this frame (probe) or computed for its time (sun)
  Held,        // not measurable on this frame (probe out of view, clipped, ...): the last estimate
  NoDirect,    // no direct light (the sun is below the horizon): ambient only, no shadow pass
  None,        // nothing known yet (no probe seen so far)
};
std::string_view light_state_name(LightState state);

struct LightEstimate {
  LightState state = LightState::None;
  std::string source = "fixed";          // "fixed", "mirror-probe", "diffuse-probe" or "sun"
  std::vector<DirectionalLight> lights;  // strongest first
  ShRgb9 ambient_sh{};                   // the light not in `lights`: radiance SH, world frame
  bool scene_linear = false;             // units as above (false: nothing estimated yet)
  double confidence = 0;                 // [0, 1]: how far the estimate can be trusted
  int frames_since_measured = 0;         // Held: frames since the last measurement
  // Estimated: frames since this estimate was measured, each frame's own measurement having been
  // within light.probe.hold_* of it (core/light/light_hold.h); 0: measured on this frame.
  int frames_kept = 0;
  std::string note;                      // why Held / NoDirect / low confidence, for the results
};

}  // namespace arpipe
