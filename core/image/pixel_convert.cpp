#include "core/image/pixel_convert.h"

#include <algorithm>
#include <cstring>

#include "core/image/bayer.h"
#include "core/image/srgb.h"
#include "core/image/yuv_rows.h"

namespace arpipe {

namespace {
inline uint8_t clamp8(int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); }

inline uint8_t rgb_to_y(int r, int g, int b) { return clamp8(((66 * r + 129 * g + 25 * b + 128) >> 8) + 16); }
// Full-range BT.601 luma (0.299, 0.587, 0.114 in 8-bit fixed point; the weights sum to 256, so a
// grey stays exactly the same grey). GREY frames are full range: 0 is black, 255 is white.
inline uint8_t rgb_to_full_range_luma(int r, int g, int b) { return uint8_t((77 * r + 150 * g + 29 * b + 128) >> 8); }
inline uint8_t rgb_to_u(int r, int g, int b) { return clamp8(((-38 * r - 74 * g + 112 * b + 128) >> 8) + 128); }
inline uint8_t rgb_to_v(int r, int g, int b) { return clamp8(((112 * r - 94 * g - 18 * b + 128) >> 8) + 128); }
}  // namespace

void to_grey(const Frame& f, std::vector<uint8_t>& out) { to_grey(f, PixelRect::full(f.width, f.height), out); }

void to_grey(const Frame& f, const PixelRect& rect, std::vector<uint8_t>& out) {
  out.resize(size_t(f.width) * f.height);
  const PixelRect r = rect.intersected(PixelRect::full(f.width, f.height));
  if (is_bayer(f.format)) {
    // Demosaicing needs the neighbours, so the whole frame is developed and the rect's luma taken
    // from it: the same luma as the frame's RGB24 would give.
    thread_local std::vector<uint8_t> rgb;
    bayer_to_rgb24(f, bayer_development(f.meta.raw), rgb);
    for (int y = r.y; y < r.bottom(); ++y)
      for (int x = r.x; x < r.right(); ++x) {
        const uint8_t* p = &rgb[(size_t(y) * f.width + x) * 3];
        out[size_t(y) * f.width + x] = rgb_to_full_range_luma(p[0], p[1], p[2]);
      }
    return;
  }
  for (int y = r.y; y < r.bottom(); ++y) {
    const uint8_t* row = f.data.data() + size_t(y) * f.bytes_per_line;
    uint8_t* dst = out.data() + size_t(y) * f.width;
    switch (f.format) {
      case PixelFormat::GREY:
      case PixelFormat::NV12: std::memcpy(dst + r.x, row + r.x, size_t(r.width)); break;
      case PixelFormat::YUYV:
        for (int x = r.x; x < r.right(); ++x) dst[x] = row[2 * x];
        break;
      case PixelFormat::RGB24:
        for (int x = r.x; x < r.right(); ++x) dst[x] = rgb_to_full_range_luma(row[3 * x], row[3 * x + 1], row[3 * x + 2]);
        break;
      default: break;  // Bayer: above
    }
  }
}

void to_rgb24(const Frame& f, std::vector<uint8_t>& out) {
  if (is_bayer(f.format)) {
    bayer_to_rgb24(f, bayer_development(f.meta.raw), out);
    return;
  }
  out.resize(size_t(f.width) * f.height * 3);
  const uint8_t* uv_plane = f.data.data() + f.bytes_per_line * size_t(f.height);
  for (int y = 0; y < f.height; ++y) {
    const uint8_t* row = f.data.data() + size_t(y) * f.bytes_per_line;
    uint8_t* dst = out.data() + size_t(y) * f.width * 3;
    switch (f.format) {
      case PixelFormat::RGB24: std::memcpy(dst, row, size_t(f.width) * 3); break;
      case PixelFormat::GREY:
        for (int x = 0; x < f.width; ++x) dst[3 * x] = dst[3 * x + 1] = dst[3 * x + 2] = row[x];
        break;
      case PixelFormat::YUYV: yuyv_row_to_rgb24(row, f.width, dst); break;
      case PixelFormat::NV12: nv12_row_to_rgb24(row, uv_plane + size_t(y / 2) * f.bytes_per_line, f.width, dst); break;
      default: break;  // Bayer: above
    }
  }
}

namespace {
// The mosaic a raw sensor with no black level would give of the sRGB image: each pixel's CFA
// channel decoded to linear and rounded to the format's depth.
Frame rgb24_to_bayer(const uint8_t* rgb, int width, int height, PixelFormat format) {
  BayerMosaic mosaic{width, height, *bayer_order(format), bayer_bit_depth(format), {}};
  mosaic.values.resize(size_t(width) * height);
  const double top = double((1 << mosaic.bit_depth) - 1);
  std::array<uint16_t, 256> code{};
  for (int v = 0; v < 256; ++v) code[size_t(v)] = uint16_t(std::lround(srgb_decode(v / 255.0) * top));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      mosaic.values[i] = code[rgb[i * 3 + size_t(mosaic.channel_at(x, y))]];
    }
  return pack_bayer(mosaic, format);
}
}  // namespace

Frame from_rgb24(const uint8_t* rgb, int width, int height, PixelFormat format) {
  if (is_bayer(format)) {
    Frame out = rgb24_to_bayer(rgb, width, height, format);
    out.meta.raw.black_level = std::array<double, 4>{0, 0, 0, 0};  // what rgb24_to_bayer codes: neutral
    out.meta.raw.gains = std::array<double, 3>{1, 1, 1};
    return out;
  }
  Frame f = Frame::allocate(format, width, height);
  auto px = [&](int x, int y) { return rgb + (size_t(y) * width + x) * 3; };
  for (int y = 0; y < height; ++y) {
    uint8_t* row = f.data.data() + size_t(y) * f.bytes_per_line;
    switch (format) {
      case PixelFormat::RGB24: std::memcpy(row, px(0, y), size_t(width) * 3); break;
      case PixelFormat::GREY:
        for (int x = 0; x < width; ++x) row[x] = rgb_to_full_range_luma(px(x, y)[0], px(x, y)[1], px(x, y)[2]);
        break;
      case PixelFormat::YUYV:
        for (int x = 0; x < width; x += 2) {
          const uint8_t* a = px(x, y);
          const uint8_t* b = px(x + 1, y);
          const int r = (a[0] + b[0] + 1) / 2, g = (a[1] + b[1] + 1) / 2, bl = (a[2] + b[2] + 1) / 2;
          row[2 * x] = rgb_to_y(a[0], a[1], a[2]);
          row[2 * x + 1] = rgb_to_u(r, g, bl);
          row[2 * x + 2] = rgb_to_y(b[0], b[1], b[2]);
          row[2 * x + 3] = rgb_to_v(r, g, bl);
        }
        break;
      case PixelFormat::NV12:
        for (int x = 0; x < width; ++x) row[x] = rgb_to_y(px(x, y)[0], px(x, y)[1], px(x, y)[2]);
        if (y % 2 == 0) {
          uint8_t* uv = f.data.data() + f.bytes_per_line * size_t(height) + size_t(y / 2) * f.bytes_per_line;
          for (int x = 0; x < width; x += 2) {
            int r = 0, g = 0, b = 0;
            for (int dy = 0; dy < 2; ++dy)
              for (int dx = 0; dx < 2; ++dx) {
                r += px(x + dx, y + dy)[0];
                g += px(x + dx, y + dy)[1];
                b += px(x + dx, y + dy)[2];
              }
            uv[x] = rgb_to_u((r + 2) / 4, (g + 2) / 4, (b + 2) / 4);
            uv[x + 1] = rgb_to_v((r + 2) / 4, (g + 2) / 4, (b + 2) / 4);
          }
        }
        break;
      default: break;  // Bayer: above
    }
  }
  return f;
}

void rgb24_to_i420(const uint8_t* rgb, int rgb_width, int width, int height, std::vector<uint8_t>& out) {
  const size_t ysize = size_t(width) * height;
  out.resize(ysize + 2 * (ysize / 4));
  uint8_t* Y = out.data();
  uint8_t* U = Y + ysize;
  uint8_t* V = U + ysize / 4;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = rgb + (size_t(y) * rgb_width + x) * 3;
      Y[size_t(y) * width + x] = rgb_to_y(p[0], p[1], p[2]);
    }
  for (int y = 0; y < height; y += 2)
    for (int x = 0; x < width; x += 2) {
      int r = 0, g = 0, b = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const uint8_t* p = rgb + (size_t(y + dy) * rgb_width + x + dx) * 3;
          r += p[0];
          g += p[1];
          b += p[2];
        }
      const size_t i = size_t(y / 2) * (width / 2) + x / 2;
      U[i] = rgb_to_u((r + 2) / 4, (g + 2) / 4, (b + 2) / 4);
      V[i] = rgb_to_v((r + 2) / 4, (g + 2) / 4, (b + 2) / 4);
    }
}

void rgb24_to_yuyv(const uint8_t* rgb, size_t rgb_bytes_per_line, int width, int height, uint8_t* out,
                   size_t out_bytes_per_line) {
  for (int y = 0; y < height; ++y) {
    const uint8_t* src = rgb + size_t(y) * rgb_bytes_per_line;
    uint8_t* row = out + size_t(y) * out_bytes_per_line;
    for (int x = 0; x + 1 < width; x += 2) {
      const uint8_t* a = src + size_t(x) * 3;
      const uint8_t* b = a + 3;
      const int r = (a[0] + b[0] + 1) / 2, g = (a[1] + b[1] + 1) / 2, bl = (a[2] + b[2] + 1) / 2;
      row[2 * x] = rgb_to_y(a[0], a[1], a[2]);
      row[2 * x + 1] = rgb_to_u(r, g, bl);
      row[2 * x + 2] = rgb_to_y(b[0], b[1], b[2]);
      row[2 * x + 3] = rgb_to_v(r, g, bl);
    }
  }
}

}  // namespace arpipe
