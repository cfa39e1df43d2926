// The environment light source (see environment_light.h).
#include "core/environment/environment_light.h"

#include <fmt/format.h>

#include "core/environment/environment_sh.h"
#include "core/environment/hdr_environment.h"
#include "core/environment/environment_layout.h"
#include "core/sh/sh_irradiance.h"
#include "core/sh/sh_window.h"

namespace arpipe {

EnvironmentLighting load_environment_lighting(const Config& config, int bands) {
  const EnvironmentConfig& c = config.light.environment;
  const std::string where = config.file.empty() ? std::string("config") : config.file.string();
  EnvironmentLighting out;
  try {
    const HdrEnvironment environment =
        HdrEnvironment::load(c.file, c.layout, default_world_from_probe(c.yaw_rad), c.scale);
    out.radiance_sh = project_environment(environment, bands);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: light.environment.file: {}", where, e.what()));
  }
  apply_sh_window(out.radiance_sh, c.window);
  out.estimate.state = LightState::Estimated;
  out.estimate.source = "environment";
  out.estimate.ambient_sh = to_sh9(out.radiance_sh);
  out.estimate.scene_linear = true;
  out.estimate.confidence = 1;
  return out;
}

}  // namespace arpipe
