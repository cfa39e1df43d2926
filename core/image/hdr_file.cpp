// Dispatch on magic bytes between the Radiance and OpenEXR readers, and the common texel check.
#include "core/image/hdr_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <unistd.h>

#include "core/config/regular_file.h"
#include "core/image/openexr_file.h"
#include "core/image/radiance_hdr.h"
#include "core/scene/asset_error.h"

namespace arpipe {

HdrImage read_hdr_image(const std::filesystem::path& file) {
  std::array<char, 4> magic{};
  {
    // Regular files only: a FIFO would block here, a device never end.
    int fd = -1;
    try {
      fd = open_regular_file(file, "HDR image");
    } catch (const FileAccessError& e) {
      throw AssetError(e.what());
    }
    size_t got = 0;
    while (got < magic.size()) {
      const ssize_t n = ::read(fd, magic.data() + got, magic.size() - got);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      got += size_t(n);
    }
    ::close(fd);
  }
  HdrImage image;
  if (magic[0] == '#' && magic[1] == '?')
    image = read_radiance_hdr(file);
  else if (magic == std::array<char, 4>{0x76, 0x2f, 0x31, 0x01})
    image = read_openexr(file);
  else
    throw AssetError(fmt::format("{}: expected a Radiance .hdr or OpenEXR .exr file (magic \"#?\" or 76 2f 31 01), "
                                 "found bytes {:02x} {:02x} {:02x} {:02x}",
                                 file.string(), static_cast<uint8_t>(magic[0]), static_cast<uint8_t>(magic[1]),
                                 static_cast<uint8_t>(magic[2]), static_cast<uint8_t>(magic[3])));
  check_hdr_texels(image, file.string());
  return image;
}

void check_hdr_texels(const HdrImage& image, const std::string& name) {
  if (image.width < 0 || image.height < 0 ||
      image.rgb.size() != 3 * static_cast<size_t>(image.width) * static_cast<size_t>(image.height))
    throw AssetError(fmt::format("{}: a {} x {} image needs {} floats, it has {}", name, image.width, image.height,
                                 3 * static_cast<size_t>(std::max(image.width, 0)) * static_cast<size_t>(std::max(image.height, 0)),
                                 image.rgb.size()));
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const float value = image.rgb[i];
    if (std::isfinite(value) && value >= 0) continue;
    const size_t pixel = i / 3;
    const char* what = std::isnan(value) ? "NaN" : std::isinf(value) ? "infinite" : "negative";
    throw AssetError(fmt::format("{}: pixel ({}, {}) channel {}: {} value {}; light-probe texels must be finite and "
                                 ">= 0",
                                 name, pixel % static_cast<size_t>(image.width), pixel / static_cast<size_t>(image.width),
                                 "RGB"[i % 3], what, value));
  }
}

}  // namespace arpipe
