// How the bytes of a camera's V4L2 format become a pipeline frame, in one pass straight from the
// driver's buffer: formats the pipeline carries are copied as they are; the others are reordered
// into the nearest one while copying (UYVY -> YUYV, NV21 -> NV12, YUV420 -> NV12, NV16 -> YUYV),
// so every later stage keeps its four formats. Split-plane (multi-planar, "M") formats arrive as
// one memory plane per colour plane.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/config/source_choices.h"
#include "core/frame.h"

namespace arpipe {

// What one V4L2 format is, for the capture path.
struct V4L2FrameLayout {
  enum class Kind {
    AsIs,           // the pipeline's own format (or any it knows by this FourCC): copied
    Packed422,      // Y and chroma interleaved per pixel pair, in some order -> YUYV
    SemiPlanar420,  // Y plane, then a plane of chroma pairs for each 2x2 block -> NV12
    Planar420,      // Y plane, then a U and a V plane of (w/2) x (h/2) -> NV12
    SemiPlanar422,  // Y plane, then a plane of chroma pairs for each 2x1 pair -> YUYV
  };
  uint32_t fourcc = 0;
  CaptureFormat name = CaptureFormat::Auto;  // source.pixel_format's name for it
  Kind kind = Kind::AsIs;
  int memory_planes = 1;           // buffers per frame the driver fills (2 or 3 for the "M" formats)
  PixelFormat frame_format = PixelFormat::RGB24;
  // Packed422: turns a row of `pairs` pixel pairs into Y0 U Y1 V order. Semi-planar: whether the
  // chroma pairs are V, U (NV21, NV61). Planar: whether V's plane comes before U's (YVU420).
  void (*to_yuyv)(const uint8_t* in, uint8_t* out, int pairs) = nullptr;
  bool v_first = false;
};

// The layout of a V4L2 FourCC that arpipe takes without decoding; nullopt for MJPEG and unknowns.
std::optional<V4L2FrameLayout> v4l2_frame_layout(uint32_t fourcc);
// The FourCC that source.pixel_format names (0 for auto; MJPG's is V4L2_PIX_FMT_MJPEG).
uint32_t capture_format_fourcc(CaptureFormat format);

// One memory plane of a dequeued buffer: where it is mapped, the bytes the driver filled, its stride.
struct V4L2Plane {
  const uint8_t* data = nullptr;
  size_t bytes_used = 0;
  size_t bytes_per_line = 0;
};

// Fills `frame` (format, size, stride, pixels) from the planes, reusing its memory when it holds
// enough (`allocated` says when it did not). False, with `why`, when a plane holds fewer bytes than
// the size needs (the frame is then left as it was).
bool fill_frame_from_v4l2(const V4L2FrameLayout& layout, std::span<const V4L2Plane> planes, int width, int height,
                          Frame& frame, bool& allocated, std::string& why);

}  // namespace arpipe
