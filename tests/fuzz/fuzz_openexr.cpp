// libFuzzer target: HDR light probes read from a file, as the loaders read them: read_hdr_image
// (core/image: the magic picks OpenEXR or Radiance, then the texel check), and the simulator's sky
// (capture/sim EnvironmentMap, through the same reader). Bad input must be an AssetError; a
// decoded image must hold 3 floats per pixel.
#include <cstddef>
#include <cstdint>

#include "capture/sim/sim_textures.h"
#include "core/image/hdr_file.h"
#include "core/scene/asset_error.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file = arpipe::fuzz::write_temp_file("probe.exr", data, size);
  try {
    const arpipe::HdrImage image = arpipe::read_hdr_image(file);
    ARPIPE_FUZZ_CHECK(image.width >= 1 && image.height >= 1, "a non-empty image");
    ARPIPE_FUZZ_CHECK(image.rgb.size() == 3 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height),
                      "3 floats per pixel");
  } catch (const arpipe::AssetError&) {
  }
  try {
    arpipe::sim::SimEnvironment sky;
    sky.hdr_path = file;
    sky.radiance = {1, 1, 1};
    const arpipe::sim::EnvironmentMap map(sky);
    (void)map.radiance(arpipe::Vec3{0, 0, 1});
  } catch (const arpipe::AssetError&) {
  }
  return 0;
}
