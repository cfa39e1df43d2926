// The row conversions (core/image/yuv_rows.h) against their stated fixed-point arithmetic,
// evaluated here in plain ints per pixel: every (Y, U, V) through both layouts, and every row
// width from 1 to 67, so the vector part, the scalar tail and the place where one hands over to the
// other are each checked, on random bytes.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "core/image/yuv_rows.h"

namespace arpipe {
namespace {

struct Bytes {
  uint8_t r, g, b;
  bool operator==(const Bytes&) const = default;
};

// The header's arithmetic, written out.
Bytes fixed_point(int y, int u, int v) {
  const int c = 298 * (y - 16), d = u - 128, e = v - 128;
  const auto clamp = [](int x) { return uint8_t(x < 0 ? 0 : x > 255 ? 255 : x); };
  return {clamp((c + 409 * e + 128) >> 8), clamp((c - 100 * d - 208 * e + 128) >> 8), clamp((c + 516 * d + 128) >> 8)};
}

Bytes at(const std::vector<uint8_t>& rgb, int x) { return {rgb[3 * size_t(x)], rgb[3 * size_t(x) + 1], rgb[3 * size_t(x) + 2]}; }

TEST(YuvRows, EveryTripleIsTheFixedPointArithmetic) {
  // One row per (U, V): 256 pixels, Y running 0..255 (pairs share the chroma).
  std::vector<uint8_t> yuyv(2 * 256), luma(256), chroma(256), a(3 * 256), b(3 * 256);
  int wrong = 0;
  for (int u = 0; u < 256; ++u)
    for (int v = 0; v < 256; ++v) {
      for (int x = 0; x < 256; ++x) {
        const int y = (x * 131 + u + 7 * v) & 255;  // every Y in every row, in a different order per row
        yuyv[2 * size_t(x)] = luma[size_t(x)] = uint8_t(y);
        yuyv[2 * size_t(x) + 1] = chroma[size_t(x)] = uint8_t(x % 2 == 0 ? u : v);
      }
      yuyv_row_to_rgb24(yuyv.data(), 256, a.data());
      nv12_row_to_rgb24(luma.data(), chroma.data(), 256, b.data());
      for (int x = 0; x < 256 && wrong < 10; ++x) {
        const Bytes want = fixed_point(luma[size_t(x)], u, v);
        if (!(at(a, x) == want) || !(at(b, x) == want)) {
          ++wrong;
          ADD_FAILURE() << "Y " << int(luma[size_t(x)]) << " U " << u << " V " << v;
        }
      }
    }
  EXPECT_EQ(wrong, 0);
}

TEST(YuvRows, EveryWidthFromOneTo67OnRandomBytes) {
  std::mt19937 random(20261203);
  for (int width = 1; width <= 67; ++width)
    for (int trial = 0; trial < 20; ++trial) {
      const int pairs = (width + 1) / 2;
      std::vector<uint8_t> yuyv(4 * size_t(pairs)), luma(static_cast<size_t>(width)), chroma(2 * size_t(pairs));
      for (uint8_t& byte : yuyv) byte = uint8_t(random());
      for (uint8_t& byte : luma) byte = uint8_t(random());
      for (uint8_t& byte : chroma) byte = uint8_t(random());
      std::vector<uint8_t> a(3 * size_t(width)), b(3 * size_t(width));
      yuyv_row_to_rgb24(yuyv.data(), width, a.data());
      nv12_row_to_rgb24(luma.data(), chroma.data(), width, b.data());
      for (int x = 0; x < width; ++x) {
        const size_t pair = size_t(x / 2);
        ASSERT_EQ(at(a, x), fixed_point(yuyv[2 * size_t(x)], yuyv[4 * pair + 1], yuyv[4 * pair + 3]))
            << "YUYV width " << width << " x " << x;
        ASSERT_EQ(at(b, x), fixed_point(luma[size_t(x)], chroma[2 * pair], chroma[2 * pair + 1]))
            << "NV12 width " << width << " x " << x;
      }
    }
}

}  // namespace
}  // namespace arpipe
