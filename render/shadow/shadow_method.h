// The shadow-map filters render.shadows.method names (docs/ARCHITECTURE.md, "Shadows"): from the
// seed's hard test, PCF and variance shadow maps (float, and 8-bit packed for GLES 2-class parts)
// to PCSS, whose penumbra follows the light's angular size.
#pragma once

#include <string_view>

namespace arpipe {

enum class ShadowMethod { Off, Hard, Pcf, Pcss, Vsm, VsmPacked };
inline constexpr std::string_view kShadowMethodNames = "\"off\", \"hard\", \"pcf\", \"pcss\", \"vsm\", \"vsm-packed\"";
ShadowMethod parse_shadow_method(std::string_view name);  // throws ConfigError
std::string_view shadow_method_name(ShadowMethod method);
// VSM stores moments in a colour texture; the others a depth texture.
inline bool is_variance_method(ShadowMethod m) { return m == ShadowMethod::Vsm || m == ShadowMethod::VsmPacked; }

}  // namespace arpipe
