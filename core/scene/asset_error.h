// AssetError: a scene asset (mesh, texture, HDR image) is missing or malformed; what() names the
// file and what was wrong. Shared by the renderer and the simulator, which load the same assets.
#pragma once

#include <stdexcept>

namespace arpipe {

class AssetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arpipe
