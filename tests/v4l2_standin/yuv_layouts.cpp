#include "yuv_layouts.h"

#include <cstring>

namespace arpipe::standin {

bool derived_from_yuyv(DerivedLayout layout) {
  return layout == DerivedLayout::Uyvy || layout == DerivedLayout::Yvyu || layout == DerivedLayout::Nv16;
}

size_t derived_bytes(DerivedLayout layout, int width, int height) {
  const size_t pixels = size_t(width) * size_t(height);
  return derived_from_yuyv(layout) ? pixels * 2 : pixels + pixels / 2;
}

namespace {

// YUYV's four bytes of a pixel pair (Y0 U Y1 V) into UYVY (U Y0 V Y1), YVYU (Y0 V Y1 U), or NV16
// (Y0 Y1 into the Y plane, U V into the chroma plane, row for row).
void from_yuyv(DerivedLayout layout, const uint8_t* src, size_t stride, int width, int height, uint8_t* dst) {
  const size_t row_bytes = size_t(width) * 2;
  uint8_t* y_plane = dst;
  uint8_t* uv_plane = dst + size_t(width) * size_t(height);
  for (int r = 0; r < height; ++r) {
    const uint8_t* s = src + size_t(r) * stride;
    uint8_t* d = dst + size_t(r) * row_bytes;
    for (int x = 0; x < width; x += 2, s += 4) {
      const uint8_t y0 = s[0], u = s[1], y1 = s[2], v = s[3];
      switch (layout) {
        case DerivedLayout::Uyvy: d[0] = u, d[1] = y0, d[2] = v, d[3] = y1, d += 4; break;
        case DerivedLayout::Yvyu: d[0] = y0, d[1] = v, d[2] = y1, d[3] = u, d += 4; break;
        default: {
          const size_t at = size_t(r) * size_t(width) + size_t(x);
          y_plane[at] = y0, y_plane[at + 1] = y1, uv_plane[at] = u, uv_plane[at + 1] = v;
        }
      }
    }
  }
}

// NV12's Y plane stays; its interleaved U V plane becomes V U (NV21) or a U plane then a V plane (YU12).
void from_nv12(DerivedLayout layout, const uint8_t* src, size_t stride, int width, int height, uint8_t* dst) {
  for (int r = 0; r < height; ++r) std::memcpy(dst + size_t(r) * size_t(width), src + size_t(r) * stride, size_t(width));
  const uint8_t* uv = src + stride * size_t(height);
  uint8_t* chroma = dst + size_t(width) * size_t(height);
  const size_t cw = size_t(width) / 2, ch = size_t(height) / 2;
  for (size_t r = 0; r < ch; ++r) {
    const uint8_t* s = uv + r * stride;
    for (size_t c = 0; c < cw; ++c) {
      if (layout == DerivedLayout::Nv21) {
        chroma[r * size_t(width) + 2 * c] = s[2 * c + 1];
        chroma[r * size_t(width) + 2 * c + 1] = s[2 * c];
      } else {
        chroma[r * cw + c] = s[2 * c];
        chroma[cw * ch + r * cw + c] = s[2 * c + 1];
      }
    }
  }
}

}  // namespace

void derive_layout(DerivedLayout layout, const uint8_t* src, size_t src_stride, int width, int height, uint8_t* dst) {
  if (derived_from_yuyv(layout))
    from_yuyv(layout, src, src_stride, width, height, dst);
  else
    from_nv12(layout, src, src_stride, width, height, dst);
}

}  // namespace arpipe::standin
