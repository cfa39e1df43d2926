// libFuzzer target: Radiance .hdr (RGBE) light probes (core/image decode_radiance_hdr, the bytes
// behind read_radiance_hdr), then the texel check every HDR input goes through. Bad input must
// be an AssetError; a decoded image must hold 3 floats per pixel within the documented sides.
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/image/hdr_file.h"
#include "core/image/radiance_hdr.h"
#include "core/scene/asset_error.h"
#include "tests/fuzz/fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const arpipe::HdrImage image = arpipe::decode_radiance_hdr(std::span<const uint8_t>(data, size), "fuzz.hdr");
    ARPIPE_FUZZ_CHECK(image.width >= 1 && image.width <= 32768 && image.height >= 1 && image.height <= 32768,
                      "sides 1..32768");
    ARPIPE_FUZZ_CHECK(image.rgb.size() == 3 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height),
                      "3 floats per pixel");
    arpipe::check_hdr_texels(image, "fuzz.hdr");
  } catch (const arpipe::AssetError&) {
  }
  return 0;
}
