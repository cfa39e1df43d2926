#include "capture/v4l2/v4l2_frame_layout.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <array>
#include <cstring>

#include <fmt/format.h>

#include "core/pixel_format.h"

namespace arpipe {
namespace {

using Kind = V4L2FrameLayout::Kind;

uint32_t load32(const uint8_t* p) {
  uint32_t x;
  std::memcpy(&x, p, 4);
  return x;
}

// Y0 U Y1 V from another order of the four bytes of each pixel pair, with the byte positions fixed
// at compile time so that the loop is a few vector shifts and masks.
template <unsigned Y0, unsigned U, unsigned Y1, unsigned V>
void reorder_pairs(const uint8_t* in, uint8_t* out, int pairs) {
  for (int i = 0; i < pairs; ++i) {
    const uint32_t x = load32(in + 4 * i);
    const uint32_t y = ((x >> (8 * Y0)) & 0xff) | (((x >> (8 * U)) & 0xff) << 8) | (((x >> (8 * Y1)) & 0xff) << 16) |
                       (((x >> (8 * V)) & 0xff) << 24);
    std::memcpy(out + 4 * i, &y, 4);
  }
}

V4L2FrameLayout packed(uint32_t fourcc, CaptureFormat name, void (*to_yuyv)(const uint8_t*, uint8_t*, int)) {
  V4L2FrameLayout l{fourcc, name, Kind::Packed422, 1, PixelFormat::YUYV};
  l.to_yuyv = to_yuyv;
  return l;
}
V4L2FrameLayout planes(uint32_t fourcc, CaptureFormat name, Kind kind, int memory_planes, bool v_first) {
  const PixelFormat to = kind == Kind::SemiPlanar422 ? PixelFormat::YUYV : PixelFormat::NV12;
  V4L2FrameLayout l{fourcc, name, kind, memory_planes, to};
  l.v_first = v_first;
  return l;
}

// The formats taken by reordering; the pipeline's own come from core/pixel_format.h.
const std::array kConverted = {
    packed(V4L2_PIX_FMT_UYVY, CaptureFormat::UYVY, reorder_pairs<1, 0, 3, 2>),  // U Y0 V Y1
    packed(V4L2_PIX_FMT_YVYU, CaptureFormat::YVYU, reorder_pairs<0, 3, 2, 1>),  // Y0 V Y1 U
    planes(V4L2_PIX_FMT_NV21, CaptureFormat::NV21, Kind::SemiPlanar420, 1, true),
    planes(V4L2_PIX_FMT_YUV420, CaptureFormat::YUV420, Kind::Planar420, 1, false),
    planes(V4L2_PIX_FMT_NV16, CaptureFormat::NV16, Kind::SemiPlanar422, 1, false),
    planes(V4L2_PIX_FMT_NV12M, CaptureFormat::NV12M, Kind::SemiPlanar420, 2, false),
    planes(V4L2_PIX_FMT_NV21M, CaptureFormat::NV21M, Kind::SemiPlanar420, 2, true),
    planes(V4L2_PIX_FMT_YUV420M, CaptureFormat::YUV420M, Kind::Planar420, 3, false),
    planes(V4L2_PIX_FMT_NV16M, CaptureFormat::NV16M, Kind::SemiPlanar422, 2, false),
};

// One colour plane of a frame in the driver's memory: where its first row starts and the stride.
struct Rows {
  const uint8_t* data = nullptr;
  size_t stride = 0;
};

// Where colour plane `index` (rows x row_bytes) lies, checked against what the driver filled.
// Contiguous formats keep their planes one after another in memory plane 0, each following the
// one before at the stride the first plane's gives (halved for a planar format's chroma).
bool locate(std::span<const V4L2Plane> planes, int memory_planes, int index, size_t rows, size_t row_bytes,
            size_t luma_rows, size_t chroma_stride_divisor, Rows& out, std::string& why) {
  const bool split = memory_planes > 1;
  const V4L2Plane& plane = planes[split ? size_t(index) : 0];
  size_t offset = 0;
  size_t stride = plane.bytes_per_line;
  if (!split) {
    const size_t luma_stride = plane.bytes_per_line;
    const size_t chroma_stride = luma_stride / chroma_stride_divisor;
    if (index > 0) {
      offset = luma_stride * luma_rows;
      stride = chroma_stride;
    }
    if (index > 1) offset += chroma_stride * rows;
  }
  if (stride == 0) stride = row_bytes;  // a driver that leaves it 0: rows packed
  const size_t needed = offset + stride * (rows - 1) + row_bytes;
  if (stride < row_bytes || plane.bytes_used < needed) {
    why = fmt::format("plane {}: {} bytes (stride {}), its {} rows of {} need {}", index, plane.bytes_used, stride, rows,
                      row_bytes, needed);
    return false;
  }
  out = {plane.data + offset, stride};
  return true;
}

// U V pairs from V U pairs (NV21, NV61): a byte swap of each 16-bit word.
void swap_pairs(const uint8_t* in, uint8_t* out, int pairs) {
  for (int i = 0; i < pairs; ++i) {
    uint16_t x;
    std::memcpy(&x, in + 2 * i, 2);
    x = uint16_t((x << 8) | (x >> 8));
    std::memcpy(out + 2 * i, &x, 2);
  }
}

}  // namespace

std::optional<V4L2FrameLayout> v4l2_frame_layout(uint32_t fourcc) {
  if (const auto own = pixel_format_from_fourcc(fourcc)) {
    V4L2FrameLayout l{fourcc, CaptureFormat::Auto, Kind::AsIs, 1, *own};
    for (const auto& choice : kCaptureFormatNames)
      if (frame_format(choice.value) == own) l.name = choice.value;
    return l;
  }
  for (const auto& l : kConverted)
    if (l.fourcc == fourcc) return l;
  return std::nullopt;
}

uint32_t capture_format_fourcc(CaptureFormat format) {
  if (format == CaptureFormat::Auto) return 0;
  if (format == CaptureFormat::MJPG) return V4L2_PIX_FMT_MJPEG;
  if (const auto own = frame_format(format)) return pixel_format_fourcc(*own);
  for (const auto& l : kConverted)
    if (l.name == format) return l.fourcc;
  return 0;
}

bool fill_frame_from_v4l2(const V4L2FrameLayout& l, std::span<const V4L2Plane> planes, int width, int height,
                          Frame& frame, bool& allocated, std::string& why) {
  allocated = false;
  if (planes.size() != size_t(l.memory_planes) || width <= 0 || height <= 0) {
    why = fmt::format("{} planes for a {}-plane format", planes.size(), l.memory_planes);
    return false;
  }
  if (const auto bad = check_image_size(l.frame_format, width, height)) {
    why = *bad;
    return false;
  }
  const size_t w = size_t(width), h = size_t(height);
  if (l.kind == Kind::AsIs) {
    const size_t stride = std::max(planes[0].bytes_per_line, min_bytes_per_line(l.frame_format, width));
    const size_t bytes = image_bytes(l.frame_format, width, height, stride);
    if (planes[0].bytes_used < bytes) {
      why = fmt::format("{} bytes, a frame needs {}", planes[0].bytes_used, bytes);
      return false;
    }
    allocated = frame.reshape(l.frame_format, width, height, stride);
    std::memcpy(frame.data.data(), planes[0].data, bytes);
    return true;
  }

  // The reordering formats: the frame gets the minimum stride.
  const bool is420 = l.kind == Kind::SemiPlanar420 || l.kind == Kind::Planar420;
  const size_t chroma_rows = is420 ? h / 2 : h;
  Rows y{}, c1{}, c2{};
  if (l.kind == Kind::Packed422) {
    if (!locate(planes, 1, 0, h, 2 * w, h, 1, y, why)) return false;
  } else if (!locate(planes, l.memory_planes, 0, h, w, h, 1, y, why)) {
    return false;
  } else if (l.kind == Kind::Planar420) {
    if (!locate(planes, l.memory_planes, 1, chroma_rows, w / 2, h, 2, c1, why) ||
        !locate(planes, l.memory_planes, 2, chroma_rows, w / 2, h, 2, c2, why))
      return false;
    if (l.v_first) std::swap(c1, c2);
  } else if (!locate(planes, l.memory_planes, 1, chroma_rows, w, h, 1, c1, why)) {
    return false;
  }
  const size_t out_stride = min_bytes_per_line(l.frame_format, width);
  allocated = frame.reshape(l.frame_format, width, height, out_stride);
  uint8_t* out = frame.data.data();
  switch (l.kind) {
    case Kind::Packed422:
      for (size_t r = 0; r < h; ++r) l.to_yuyv(y.data + r * y.stride, out + r * out_stride, width / 2);
      break;
    case Kind::SemiPlanar420:
    case Kind::Planar420: {
      for (size_t r = 0; r < h; ++r) std::memcpy(out + r * out_stride, y.data + r * y.stride, w);
      uint8_t* uv = out + h * out_stride;
      for (size_t r = 0; r < chroma_rows; ++r) {
        uint8_t* row = uv + r * out_stride;
        if (l.kind == Kind::Planar420) {
          const uint8_t* u = c1.data + r * c1.stride;
          const uint8_t* v = c2.data + r * c2.stride;
          for (size_t i = 0; i < w / 2; ++i) {
            row[2 * i] = u[i];
            row[2 * i + 1] = v[i];
          }
        } else if (l.v_first) {
          swap_pairs(c1.data + r * c1.stride, row, width / 2);
        } else {
          std::memcpy(row, c1.data + r * c1.stride, w);
        }
      }
      break;
    }
    case Kind::SemiPlanar422: {
      const size_t iu = l.v_first ? 1 : 0, iv = 1 - iu;
      for (size_t r = 0; r < h; ++r) {
        const uint8_t* luma = y.data + r * y.stride;
        const uint8_t* chroma = c1.data + r * c1.stride;
        uint8_t* row = out + r * out_stride;
        for (size_t i = 0; i < w / 2; ++i) {
          row[4 * i] = luma[2 * i];
          row[4 * i + 1] = chroma[2 * i + iu];
          row[4 * i + 2] = luma[2 * i + 1];
          row[4 * i + 3] = chroma[2 * i + iv];
        }
      }
      break;
    }
    case Kind::AsIs: break;
  }
  return true;
}

}  // namespace arpipe
