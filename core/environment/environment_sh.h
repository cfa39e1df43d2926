// The spherical-harmonic projection of an HDR light probe by exact per-texel integration: every
// valid texel adds radiance * y_i(direction) * its solid angle.
#pragma once

#include "core/environment/hdr_environment.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

// Radiance SH of the environment in the world frame (the probe's placement and scale applied).
ShRgb project_environment(const HdrEnvironment& environment, int bands);

}  // namespace arpipe
