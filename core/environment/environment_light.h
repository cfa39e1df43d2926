// light.source = "environment": an HDR light probe file is the whole light. Loaded and projected
// onto spherical harmonics once at configure; every frame then carries the same estimate.
#pragma once

#include "core/config/config.h"
#include "core/light/light_estimate.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

struct EnvironmentLighting {
  ShRgb radiance_sh;       // world frame, scene-linear units, windowed, as many bands as asked
  LightEstimate estimate;  // its first 3 bands as the ambient light, no directional light
};

// Reads light.environment.file (relative paths from the working directory, like every path in a
// config). Throws ConfigError naming the file and the key for a missing or malformed image or a
// layout its shape does not fit.
EnvironmentLighting load_environment_lighting(const Config& config, int bands = 3);

}  // namespace arpipe
