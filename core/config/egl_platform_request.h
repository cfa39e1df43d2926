// Which EGL platform the render stage asks for (config key render.egl_platform), with its one name
// table; render/gl/egl_context.h says which one it got (EglPlatform).
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class EglPlatformRequest {
  Auto,         // a device when the EGL device platform lists one, else surfaceless
  Surfaceless,  // Mesa's surfaceless platform
  Device,       // the EGL device platform
};

inline constexpr ChoiceName<EglPlatformRequest> kEglPlatformRequestNames[] = {
    {"auto", EglPlatformRequest::Auto},
    {"surfaceless", EglPlatformRequest::Surfaceless},
    {"device", EglPlatformRequest::Device}};

inline std::string_view egl_platform_request_name(EglPlatformRequest request) {
  return choice_name(kEglPlatformRequestNames, request);
}

}  // namespace arpipe
