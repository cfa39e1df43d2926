// libFuzzer target: the simulator's scene files (capture/sim parse_sim_scene, the text behind
// load_sim_scene). Relative paths resolve in an empty scratch directory. Bad input must be a
// SceneError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "capture/sim/sim_scene_loader.h"
#include "tests/fuzz/fuzz_temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)arpipe::sim::parse_sim_scene(text, "fuzz.toml", arpipe::fuzz::temp_dir());
  } catch (const arpipe::sim::SceneError&) {
  }
  return 0;
}
