// Exceptions of the render library: RenderError when the GL/EGL side cannot do what was asked,
// AssetError when a mesh file is missing or malformed (what() names the file and what was wrong).
#pragma once

#include <stdexcept>

namespace arpipe {

class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class AssetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arpipe
