// The shadow-map filters (config key render.shadows.method; docs/ARCHITECTURE.md, "Shadows"), with
// their one name table: from the seed's hard test, PCF and variance shadow maps (float, and 8-bit
// packed for GLES 2-class parts) to PCSS, whose penumbra follows the light's angular size.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class ShadowMethod { Off, Hard, Pcf, Pcss, Vsm, VsmPacked };

inline constexpr ChoiceName<ShadowMethod> kShadowMethodNames[] = {
    {"off", ShadowMethod::Off}, {"hard", ShadowMethod::Hard}, {"pcf", ShadowMethod::Pcf},
    {"pcss", ShadowMethod::Pcss}, {"vsm", ShadowMethod::Vsm}, {"vsm-packed", ShadowMethod::VsmPacked}};

inline std::string_view shadow_method_name(ShadowMethod method) { return choice_name(kShadowMethodNames, method); }
// VSM stores moments in a colour texture; the others a depth texture.
inline bool is_variance_method(ShadowMethod m) { return m == ShadowMethod::Vsm || m == ShadowMethod::VsmPacked; }

}  // namespace arpipe
