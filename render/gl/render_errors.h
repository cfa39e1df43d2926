// Exceptions of the render library: RenderError when the GL/EGL side cannot do what was asked,
// AssetError (core/scene/asset_error.h) when a mesh file is missing or malformed.
#pragma once

#include <stdexcept>

#include "core/scene/asset_error.h"

namespace arpipe {

class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arpipe
