// Videos whose frames carry their own index, for checking that a frame's index (and what follows
// from it: the animation's time) is the one drawn in: frame i is grey with bit b of i as a 16 x 64
// block (white 1, black 0) at column 16 b, made with Debian's ffmpeg command at 30 frames/s.
#pragma once

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace arpipe::test {

inline constexpr int kBarcodeWidth = 256, kBarcodeHeight = 128, kBarcodeBits = 12;

inline std::vector<uint8_t> barcode_frame(int i) {
  std::vector<uint8_t> rgb(size_t(kBarcodeWidth) * kBarcodeHeight * 3, 128);
  for (int b = 0; b < kBarcodeBits; ++b)
    for (int y = 32; y < 96; ++y)
      for (int x = 16 * b; x < 16 * b + 16; ++x)
        for (int c = 0; c < 3; ++c) rgb[(size_t(y) * kBarcodeWidth + size_t(x)) * 3 + size_t(c)] = (i >> b) & 1 ? 255 : 0;
  return rgb;
}

// The index drawn into a decoded frame's RGB (rows of `width` pixels).
inline int read_barcode(const std::vector<uint8_t>& rgb, int width) {
  int i = 0;
  for (int b = 0; b < kBarcodeBits; ++b)
    if (rgb[(size_t(64) * size_t(width) + size_t(16 * b + 8)) * 3] > 128) i |= 1 << b;
  return i;
}

// Encodes `frames` barcoded frames at 30 frames/s with ffmpeg's arguments `codec` into dir / name.
inline std::filesystem::path make_barcode_video(const std::filesystem::path& dir, const std::string& name, int frames,
                                                const std::string& codec) {
  const std::filesystem::path raw = dir / (name + ".rgb"), out = dir / name;
  {
    std::ofstream file(raw, std::ios::binary);
    for (int i = 0; i < frames; ++i) {
      const std::vector<uint8_t> rgb = barcode_frame(i);
      file.write(reinterpret_cast<const char*>(rgb.data()), std::streamsize(rgb.size()));
    }
  }
  const std::string command = fmt::format(
      "ffmpeg -nostdin -v error -y -f rawvideo -pix_fmt rgb24 -s {}x{} -r 30 -i '{}' {} -pix_fmt yuv420p '{}'",
      kBarcodeWidth, kBarcodeHeight, raw.string(), codec, out.string());
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::filesystem::remove(raw);
  return out;
}

// x264 with 3 B-frames and a key frame every 20: the MP4 edit list delays its start by two frames.
inline constexpr const char* kH264WithBFrames = "-c:v libx264 -preset veryfast -bf 3 -g 20 -crf 12";

}  // namespace arpipe::test
