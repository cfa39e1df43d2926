// configs/sim/proxies.toml's world as scene-file text, for the panorama tests that simulate it from
// their own cameras: its objects, lights and sky, and the tables they simulate it with.
#pragma once

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace arpipe::test {

// From its first [[object]] on, with or without the virtual cube.
inline std::string proxies_world(bool with_virtual_cube) {
  std::ifstream in(std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs/sim/proxies.toml");
  std::stringstream text;
  text << in.rdbuf();
  std::string objects = text.str().substr(text.str().find("[[object]]"));
  if (!with_virtual_cube) {
    const size_t cube = objects.find("[[object]]\nname = \"virtual-cube\"");
    objects.erase(cube, objects.find("[[light]]") - cube);
  }
  return objects;
}

// A noiseless sensor, `samples` rays a pixel, `frames` frames, seed 1, a keyframed trajectory (the
// caller adds its keyframes).
inline std::string proxies_world_sections(int samples, int frames) {
  return fmt::format("[camera.sensor]\nnoise = false\n[render]\nsamples_per_pixel = {}\nframes = {}\nseed = 1\n"
                     "[trajectory]\nkind = \"keyframes\"\n",
                     samples, frames);
}

}  // namespace arpipe::test
