// The size a PNG or JPEG file declares, read from its header (PNG IHDR, JPEG SOFn) without
// decoding: so a loader can refuse a 30000 x 30000 image in a 1 MB file before allocating for it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace arpipe {

struct ImageHeader {
  std::string format;  // "PNG" or "JPEG"
  int64_t width = 0;
  int64_t height = 0;
};

// Reads the header of a PNG or JPEG file (regular files only, core/config/regular_file.h). Throws
// AssetError naming the file and the byte offset for anything else: another format, a header cut
// off, a JPEG whose height comes later (DNL) or that has no frame header before its scan.
ImageHeader read_image_header(const std::filesystem::path& path);

// Throws AssetError "<what> "<path>": <W> x <H> <format> image exceeds the limit of <max_side>
// pixels a side / <max_pixels> pixels" when the header declares more.
void check_image_limits(const ImageHeader& header, const std::filesystem::path& path, const std::string& what,
                        int64_t max_side, int64_t max_pixels);

}  // namespace arpipe
