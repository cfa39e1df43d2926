#include "core/image/yuv_rows.h"

#include <cstring>

namespace arpipe {
namespace {

// The scalar form: the rows' tails, and the reference the vector form equals.
inline uint8_t yuv_clamp8(int v) { return uint8_t(v < 0 ? 0 : v > 255 ? 255 : v); }
inline void decode_yuv_pixel(int y, int u, int v, uint8_t* rgb) {
  const int c = 298 * (y - 16) + 128, d = u - 128, e = v - 128;
  rgb[0] = yuv_clamp8((c + 409 * e) >> 8);
  rgb[1] = yuv_clamp8((c - 100 * d - 208 * e) >> 8);
  rgb[2] = yuv_clamp8((c + 516 * d) >> 8);
}

using u8x16 = uint8_t __attribute__((vector_size(16)));
using i16x8 = int16_t __attribute__((vector_size(16)));
using u16x8 = uint16_t __attribute__((vector_size(16)));
using u32x4 = uint32_t __attribute__((vector_size(16)));

// Eight pixels as YUYV in 16-bit lanes (Y low byte, U or V high byte) to R, G, B before clamping.
// R = 298 y' + 409 e + 128 >> 8 = y' + e + (42 y' + 153 e + 128 >> 8), and so for G and B: the
// remainders stay within +-2^15 for every byte triple, and >> on a signed lane floors.
[[gnu::always_inline]] inline void decode_yuv_eight(u16x8 yuyv, i16x8& r, i16x8& g, i16x8& b) {
  const i16x8 y = i16x8(yuyv & 0xFF) - 16;
  const u32x4 uv = u32x4(yuyv >> 8);  // per pixel pair: U | V << 16
  const i16x8 d = i16x8((uv & 0xFFFF) * 0x10001u) - 128;
  const i16x8 e = i16x8((uv >> 16) * 0x10001u) - 128;
  r = y + e + ((42 * y + 153 * e + 128) >> 8);
  g = y - e + ((42 * y - 100 * d + 48 * e + 128) >> 8);
  b = y + 2 * d + ((42 * y + 4 * d + 128) >> 8);
}

// Two vectors of eight results, clamped to 0..255, as sixteen bytes.
[[gnu::always_inline]] inline u8x16 yuv_clamp_pack(i16x8 lo, i16x8 hi) {
  const i16x8 zero{}, full = zero + 255;
  lo = lo < zero ? zero : lo > full ? full : lo;
  hi = hi < zero ? zero : hi > full ? full : hi;
  return __builtin_shufflevector(u8x16(lo), u8x16(hi), 0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
}

// Sixteen pixels as YUYV (two vectors) to 48 bytes of RGB.
[[gnu::always_inline]] inline void decode_yuv_sixteen(u16x8 first, u16x8 second, uint8_t* rgb) {
  i16x8 r0, g0, b0, r1, g1, b1;
  decode_yuv_eight(first, r0, g0, b0);
  decode_yuv_eight(second, r1, g1, b1);
  const u8x16 r = yuv_clamp_pack(r0, r1), g = yuv_clamp_pack(g0, g1), b = yuv_clamp_pack(b0, b1);
  // Interleaved: r and g paired, then b slotted in after every pair.
  const u8x16 rg0 = __builtin_shufflevector(r, g, 0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const u8x16 rg1 = __builtin_shufflevector(r, g, 5, 21, 6, 22, 7, 23, 8, 24, 9, 25, 10, 26, 11, 27, 12, 28);
  const u8x16 rg2 = __builtin_shufflevector(r, g, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31, 0, 0, 0, 0);
  const u8x16 out0 = __builtin_shufflevector(rg0, b, 0, 1, 16, 2, 3, 17, 4, 5, 18, 6, 7, 19, 8, 9, 20, 10);
  const u8x16 out1 = __builtin_shufflevector(rg1, b, 1, 21, 2, 3, 22, 4, 5, 23, 6, 7, 24, 8, 9, 25, 10, 11);
  const u8x16 out2 = __builtin_shufflevector(rg2, b, 26, 2, 3, 27, 4, 5, 28, 6, 7, 29, 8, 9, 30, 10, 11, 31);
  std::memcpy(rgb, &out0, 16);
  std::memcpy(rgb + 16, &out1, 16);
  std::memcpy(rgb + 32, &out2, 16);
}

}  // namespace

// Byte shuffles are single instructions from SSSE3 on; plain SSE2 (x86-64's baseline) would
// emulate them and gain nothing, so the vector form is compiled for those and picked at run time.
#if defined(__x86_64__)
#define ARPIPE_YUV_TARGETS __attribute__((target_clones("avx2", "ssse3", "default")))
#else
#define ARPIPE_YUV_TARGETS
#endif

ARPIPE_YUV_TARGETS void yuyv_row_to_rgb24(const uint8_t* row, int width, uint8_t* rgb) {
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    u16x8 first, second;
    std::memcpy(&first, row + 2 * x, 16);
    std::memcpy(&second, row + 2 * x + 16, 16);
    decode_yuv_sixteen(first, second, rgb + 3 * x);
  }
  for (; x < width; ++x) {
    const uint8_t* pair = row + 4 * (x / 2);
    decode_yuv_pixel(row[2 * x], pair[1], pair[3], rgb + 3 * x);
  }
}

ARPIPE_YUV_TARGETS void nv12_row_to_rgb24(const uint8_t* y, const uint8_t* uv, int width, uint8_t* rgb) {
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    u8x16 luma, chroma;
    std::memcpy(&luma, y + x, 16);
    std::memcpy(&chroma, uv + x, 16);
    // As YUYV: Y0 U Y1 V ...
    const u8x16 first = __builtin_shufflevector(luma, chroma, 0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const u8x16 second = __builtin_shufflevector(luma, chroma, 8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
    decode_yuv_sixteen(u16x8(first), u16x8(second), rgb + 3 * x);
  }
  for (; x < width; ++x) decode_yuv_pixel(y[x], uv[x & ~1], uv[(x & ~1) + 1], rgb + 3 * x);
}

}  // namespace arpipe
