// Loads a simulator scene file (TOML, configs/sim/*.toml): every key checked, every error naming
// the file, the key and the line.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

#include "capture/sim/sim_scene.h"

namespace arpipe::sim {

// A bad scene file; what() reads "<file>:<line>:<col>: <dotted.key>: expected ..., found ..."
// (core/config/toml_section.h).
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Relative paths inside the file (textures, meshes, HDR images, camera models) are relative to
// the scene file's directory. Checks that they exist and can be read.
SimScene load_sim_scene(const std::filesystem::path& path);
// The same from text; relative paths are relative to base_dir.
SimScene parse_sim_scene(const std::string& text, const std::string& source_name, const std::filesystem::path& base_dir);

}  // namespace arpipe::sim
