// How a light probe sphere is read (config key light.probe.method), with its one name table; the
// methods are in core/probe (mirror_probe.h, diffuse_probe.h, brightest_components.h).
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class ProbeMethod {
  Auto,             // Environment for a mirror, Fit for a diffuse sphere
  BrightestImage,   // seeds 001/004's brightest components, image domain (direction only)
  BrightestSphere,  // seeds 001/004's brightest components, sphere domain (direction only)
  Environment,      // mirror: environment map, peaks and SH ambient
  Fit,              // diffuse: light + first-order ambient fitted to the shading
};

inline constexpr ChoiceName<ProbeMethod> kProbeMethodNames[] = {
    {"auto", ProbeMethod::Auto},
    {"environment", ProbeMethod::Environment},
    {"fit", ProbeMethod::Fit},
    {"brightest-image", ProbeMethod::BrightestImage},
    {"brightest-sphere", ProbeMethod::BrightestSphere},
    {"seed-image", ProbeMethod::BrightestImage, true},
    {"seed-sphere", ProbeMethod::BrightestSphere, true}};

inline std::string_view probe_method_name(ProbeMethod method) { return choice_name(kProbeMethodNames, method); }

}  // namespace arpipe
