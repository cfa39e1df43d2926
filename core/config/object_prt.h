// How a virtual object takes the environment light (config key render.objects[].prt), with its one
// name table: SH irradiance at each normal, or a transfer baked per vertex (render/prt).
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class ObjectPrt {
  Off,             // SH irradiance at each pixel's normal, no self-shadowing
  Unshadowed,      // baked cosine transfer
  Shadowed,        // baked, with self-shadowing
  Interreflected,  // baked, with self-shadowing plus one grey bounce
};

inline constexpr ChoiceName<ObjectPrt> kObjectPrtNames[] = {{"off", ObjectPrt::Off},
                                                            {"unshadowed", ObjectPrt::Unshadowed},
                                                            {"shadowed", ObjectPrt::Shadowed},
                                                            {"interreflected", ObjectPrt::Interreflected}};

inline std::string_view object_prt_name(ObjectPrt prt) { return choice_name(kObjectPrtNames, prt); }

}  // namespace arpipe
