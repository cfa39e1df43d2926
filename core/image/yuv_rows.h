// One row of YUYV or NV12 to packed RGB24: BT.601 limited range in 8-bit fixed point, with
// c = 298 (y - 16), d = u - 128, e = v - 128:
//   R = (c + 409 e + 128) >> 8, G = (c - 100 d - 208 e + 128) >> 8, B = (c + 516 d + 128) >> 8,
// each clamped to 0..255 (libyuv's reference arithmetic, bit for bit). Sixteen pixels at a time in
// 16-bit lanes where the CPU shuffles bytes (SSSE3 or AVX2 on x86-64, chosen at run time; NEON):
// each sum splits as 256 k + b with |b| < 2^15 (298 = 256 + 42, 409 = 256 + 153, and so on), so
// no lane overflows and the result is exact.
#pragma once

#include <cstdint>

namespace arpipe {

// row: width pixels of Y0 U Y1 V (an odd width's last pixel reads its whole pair's 4 bytes).
void yuyv_row_to_rgb24(const uint8_t* row, int width, uint8_t* rgb);
// y: width luma bytes; uv: the chroma row (U V per pair of pixels).
void nv12_row_to_rgb24(const uint8_t* y, const uint8_t* uv, int width, uint8_t* rgb);

}  // namespace arpipe
