// Where the light comes from (config key light.source), with its one name table.
#pragma once

#include "core/config/choice_names.h"

namespace arpipe {

enum class LightSource {
  Fixed,        // render.light_direction, light_color and ambient (display-referred, no estimation)
  Probe,        // a light probe sphere in view ([light.probe])
  Sun,          // place and time ([light.sun])
  Environment,  // an HDR light probe file ([light.environment])
  Panorama,     // the panorama source's own image ([light.panorama], source.type = "panorama")
};

inline constexpr ChoiceName<LightSource> kLightSourceNames[] = {{"fixed", LightSource::Fixed},
                                                                {"probe", LightSource::Probe},
                                                                {"sun", LightSource::Sun},
                                                                {"environment", LightSource::Environment},
                                                                {"panorama", LightSource::Panorama}};

inline std::string_view light_source_name(LightSource source) { return choice_name(kLightSourceNames, source); }

}  // namespace arpipe
