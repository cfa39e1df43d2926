#include "render/shadow/shadow_method.h"

#include <fmt/format.h>

#include "core/config/config.h"

namespace arpipe {

ShadowMethod parse_shadow_method(std::string_view name) {
  if (name == "off") return ShadowMethod::Off;
  if (name == "hard") return ShadowMethod::Hard;
  if (name == "pcf") return ShadowMethod::Pcf;
  if (name == "pcss") return ShadowMethod::Pcss;
  if (name == "vsm") return ShadowMethod::Vsm;
  if (name == "vsm-packed") return ShadowMethod::VsmPacked;
  throw ConfigError(fmt::format("render.shadows.method: \"{}\" is not one of {}", name, kShadowMethodNames));
}

std::string_view shadow_method_name(ShadowMethod method) {
  switch (method) {
    case ShadowMethod::Off: return "off";
    case ShadowMethod::Hard: return "hard";
    case ShadowMethod::Pcf: return "pcf";
    case ShadowMethod::Pcss: return "pcss";
    case ShadowMethod::Vsm: return "vsm";
    case ShadowMethod::VsmPacked: return "vsm-packed";
  }
  return "?";
}

}  // namespace arpipe
