#include "core/light/linear_patch.h"

#include <algorithm>
#include <cstring>

#include "core/image/bayer.h"
#include "core/image/pixel_convert.h"

namespace arpipe {

namespace {

int bytes_per_pixel(PixelFormat f) {
  switch (f) {
    case PixelFormat::GREY: return 1;
    case PixelFormat::RGB24: return 3;
    case PixelFormat::YUYV: return 2;
    case PixelFormat::NV12: return 1;
    default: break;  // Bayer: decode_bayer_patch, never cropped
  }
  return 1;
}

// Copies the aligned rectangle [x0, x0+w) x [y0, y0+h) into a small frame of the same format, so
// to_rgb24 converts it exactly as it would the whole frame (chroma pairs kept whole).
void crop(const Frame& f, int x0, int y0, int w, int h, Frame& out) {
  out.meta = f.meta;
  out.format = f.format;
  out.width = w;
  out.height = h;
  out.bytes_per_line = min_bytes_per_line(f.format, w);
  out.data.resize(image_bytes(f.format, w, h, out.bytes_per_line));
  const size_t bpp = size_t(bytes_per_pixel(f.format));
  for (int y = 0; y < h; ++y)
    std::memcpy(&out.data[size_t(y) * out.bytes_per_line], &f.data[size_t(y0 + y) * f.bytes_per_line + size_t(x0) * bpp],
                size_t(w) * bpp);
  if (f.format == PixelFormat::NV12) {
    const size_t src_uv = size_t(f.height) * f.bytes_per_line;
    const size_t dst_uv = size_t(h) * out.bytes_per_line;
    for (int y = 0; y < h / 2; ++y)
      std::memcpy(&out.data[dst_uv + size_t(y) * out.bytes_per_line],
                  &f.data[src_uv + size_t(y0 / 2 + y) * f.bytes_per_line + size_t(x0)], size_t(w));
  }
}

// Raw sensor values are linear already: the whole frame is developed (demosaicing needs the
// neighbours of the rect's edge pixels) and the rect taken straight from the linear result, with
// no response curve and no 8-bit round trip. A pixel is clipped where any channel reaches
// kRawClippedFrom of the white level.
constexpr float kRawClippedFrom = 0.98f;
bool decode_bayer_patch(const Frame& frame, const ImageRect& r, LinearPatch& out) {
  thread_local std::vector<float> linear;
  try {
    develop_bayer(frame, bayer_development(frame.meta.raw), linear);
  } catch (const std::exception&) {
    return false;  // a frame the format cannot hold: unusable, like a short buffer below
  }
  const auto scale = float(out.to_scene_linear);
  for (int y = 0; y < r.height; ++y) {
    const float* src = &linear[(size_t(y + r.y0) * size_t(frame.width) + size_t(r.x0)) * 3];
    float* dst = &out.rgb[size_t(y) * size_t(r.width) * 3];
    uint8_t* clip = &out.clipped[size_t(y) * size_t(r.width)];
    for (int x = 0; x < r.width; ++x) {
      for (int c = 0; c < 3; ++c) dst[3 * x + c] = src[3 * x + c] * scale;
      clip[x] = std::max({src[3 * x], src[3 * x + 1], src[3 * x + 2]}) >= kRawClippedFrom ? 1 : 0;
    }
  }
  return true;
}

}  // namespace

bool decode_linear_patch(const Frame& frame, const ImageRect& rect_in, const CameraResponse& response,
                         LinearPatch& out) {
  const double exposure_s = double(frame.meta.exposure_ns) * 1e-9;
  const double gain = frame.meta.total_gain();
  if (frame.empty() || !(exposure_s > 0) || !(gain > 0)) return false;
  if (image_bytes(frame.format, frame.width, frame.height, frame.bytes_per_line) > frame.data.size()) return false;
  ImageRect r = rect_in;
  const int x1 = std::min(frame.width, r.x0 + r.width), y1 = std::min(frame.height, r.y0 + r.height);
  r.x0 = std::max(0, r.x0);
  r.y0 = std::max(0, r.y0);
  r.width = x1 - r.x0;
  r.height = y1 - r.y0;
  if (r.empty()) return false;
  if (is_bayer(frame.format)) {
    out.rect = r;
    out.to_scene_linear = 1.0 / (exposure_s * gain);
    out.rgb.resize(size_t(r.width) * size_t(r.height) * 3);
    out.clipped.resize(size_t(r.width) * size_t(r.height));
    return decode_bayer_patch(frame, r, out);
  }
  // Chroma alignment: YUYV pairs columns, NV12 pairs columns and rows.
  const bool pair_x = frame.format == PixelFormat::YUYV || frame.format == PixelFormat::NV12;
  const bool pair_y = frame.format == PixelFormat::NV12;
  const int ax0 = pair_x ? r.x0 & ~1 : r.x0, ay0 = pair_y ? r.y0 & ~1 : r.y0;
  int ax1 = pair_x ? std::min(frame.width, (x1 + 1) & ~1) : x1;
  int ay1 = pair_y ? std::min(frame.height, (y1 + 1) & ~1) : y1;
  thread_local Frame cropped;
  thread_local std::vector<uint8_t> rgb8;
  crop(frame, ax0, ay0, ax1 - ax0, ay1 - ay0, cropped);
  to_rgb24(cropped, rgb8);
  const int cw = ax1 - ax0;

  out.rect = r;
  out.to_scene_linear = 1.0 / (exposure_s * gain);
  const size_t n = size_t(r.width) * size_t(r.height);
  out.rgb.resize(n * 3);
  out.clipped.resize(n);
  const float scale = float(out.to_scene_linear);
  const std::array<float, 256>& lut = response.lut();
  for (int y = 0; y < r.height; ++y) {
    const uint8_t* src = &rgb8[(size_t(y + r.y0 - ay0) * size_t(cw) + size_t(r.x0 - ax0)) * 3];
    float* dst = &out.rgb[size_t(y) * size_t(r.width) * 3];
    uint8_t* clip = &out.clipped[size_t(y) * size_t(r.width)];
    for (int x = 0; x < r.width; ++x) {
      const uint8_t a = src[3 * x], b = src[3 * x + 1], c = src[3 * x + 2];
      dst[3 * x] = lut[a] * scale;
      dst[3 * x + 1] = lut[b] * scale;
      dst[3 * x + 2] = lut[c] * scale;
      clip[x] = std::max({a, b, c}) >= CameraResponse::kClippedFrom ? 1 : 0;
    }
  }
  return true;
}

bool decode_linear_pixels(const Frame& frame, std::span<LinearPixel> pixels, const CameraResponse& response) {
  thread_local LinearPatch patch;
  const auto take = [&](LinearPixel& p) {
    if (!patch.rect.contains(p.x, p.y)) return false;
    const float* rgb = patch.at(p.x, p.y);
    std::copy(rgb, rgb + 3, p.rgb);
    p.clipped = patch.clipped_at(p.x, p.y);
    return true;
  };
  if (pixels.empty()) return decode_linear_patch(frame, {0, 0, 1, 1}, response, patch);  // the frame's checks alone
  if (is_bayer(frame.format)) {  // developed whole whatever the rectangle: one rectangle
    int x0 = pixels[0].x, y0 = pixels[0].y, x1 = x0, y1 = y0;
    for (const LinearPixel& p : pixels) {
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    if (!decode_linear_patch(frame, {x0, y0, x1 - x0 + 1, y1 - y0 + 1}, response, patch)) return false;
    return std::all_of(pixels.begin(), pixels.end(), take);
  }
  for (LinearPixel& p : pixels)
    if (!decode_linear_patch(frame, {p.x, p.y, 1, 1}, response, patch) || !take(p)) return false;
  return true;
}

}  // namespace arpipe
