// How the virtual layer is smeared over each exposure (config key render.blur.method), with its
// one name table; render/blur/motion_blur.h draws each of them.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class BlurMethod {
  Off,             // drawn sharp
  Accumulate,      // full renders spread over the exposure, averaged (the reference)
  IntraframeWarp,  // seed 000: two renders at 1/4 and 3/4 plus affine-warped samples between them
  Velocity,        // one render plus a per-pixel velocity gather (fastest)
};

inline constexpr ChoiceName<BlurMethod> kBlurMethodNames[] = {{"off", BlurMethod::Off},
                                                              {"accumulate", BlurMethod::Accumulate},
                                                              {"intraframe-warp", BlurMethod::IntraframeWarp},
                                                              {"velocity", BlurMethod::Velocity},
                                                              {"seed", BlurMethod::IntraframeWarp, true}};

// The name results.jsonl and the logs write.
inline std::string_view blur_method_name(BlurMethod method) { return choice_name(kBlurMethodNames, method); }

}  // namespace arpipe
