// The config the tracker tests were written against: the default bundle and one virtual object
// (the cube that a config without [[render.objects]] used to draw), since the tracker skips frames
// with nothing virtual in the scene.
#pragma once

#include "core/config/config.h"

namespace arpipe::test {

inline Config tracking_config() {
  Config config;
  config.render.objects = {SceneObject{}};
  return config;
}

}  // namespace arpipe::test
