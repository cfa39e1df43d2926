// Reading a PNG or JPEG file as hostile input: the size its header declares is checked against
// limits before anything is decoded, and each format goes to its own decoder (libpng,
// libjpeg-turbo), never to OpenCV's signature probing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

namespace arpipe {

struct ImageFileLimits {
  int64_t max_side = 16384;
  int64_t max_pixels = int64_t{1} << 25;
  uint64_t max_file_bytes = uint64_t{1} << 28;
};

// The image as 8-bit BGR (what cv::imread(IMREAD_COLOR) gives, without EXIF orientation: 16-bit
// samples to their high byte, alpha dropped, grey to three channels). Throws AssetError
// "<what> "<path>": ..." for a missing or unreadable file, another format, a size over the limits
// or a decoding error.
cv::Mat read_image_file(const std::filesystem::path& path, const std::string& what, const ImageFileLimits& limits);

}  // namespace arpipe
