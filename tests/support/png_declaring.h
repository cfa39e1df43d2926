// A small, valid PNG file whose header claims any size: the tests of loaders that must refuse a
// huge declared image before decoding it (simulator textures, calibration photographs).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace arpipe::test {

inline uint32_t png_crc32(const std::string& bytes) {  // PNG's CRC (ISO 3309), bitwise
  uint32_t crc = 0xffffffffu;
  for (const unsigned char c : bytes) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

inline void put_big_endian(std::string& bytes, size_t at, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[at + size_t(i)] = char((value >> (24 - 8 * i)) & 0xff);
}

// dir/name: a 4x4 PNG whose IHDR (CRC fixed up) declares width x height, so a decoder believes it.
inline std::filesystem::path png_declaring(const std::filesystem::path& dir, uint32_t width, uint32_t height,
                                           const std::string& name = "huge.png") {
  const std::filesystem::path path = dir / name;
  EXPECT_TRUE(cv::imwrite(path.string(), cv::Mat(4, 4, CV_8UC3, cv::Scalar(10, 20, 30))));
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  put_big_endian(bytes, 16, width);
  put_big_endian(bytes, 20, height);
  put_big_endian(bytes, 29, png_crc32(bytes.substr(12, 17)));  // over "IHDR" and its 13 data bytes
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

}  // namespace arpipe::test
