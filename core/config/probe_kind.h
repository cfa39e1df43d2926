// What a light probe sphere is made of (config key light.probe.kind), with its one name table.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class ProbeKind { Mirror, Diffuse };

inline constexpr ChoiceName<ProbeKind> kProbeKindNames[] = {{"mirror", ProbeKind::Mirror},
                                                            {"diffuse", ProbeKind::Diffuse}};

inline std::string_view probe_kind_name(ProbeKind kind) { return choice_name(kProbeKindNames, kind); }

}  // namespace arpipe
