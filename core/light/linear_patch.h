// A rectangle of a camera frame decoded to scene-linear float RGB (light_estimate.h's units:
// linear / (exposure_s * total gain)) with a per-pixel clipped flag, for the light probes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/frame.h"
#include "core/image/camera_response.h"

namespace arpipe {

struct ImageRect {
  int x0 = 0, y0 = 0, width = 0, height = 0;
  bool empty() const { return width <= 0 || height <= 0; }
  bool contains(int x, int y) const { return x >= x0 && y >= y0 && x < x0 + width && y < y0 + height; }
};

struct LinearPatch {
  ImageRect rect;             // in image pixels (clipped to the image)
  std::vector<float> rgb;     // rect.width * rect.height * 3, scene-linear
  std::vector<uint8_t> clipped;  // 1 where any channel's 8-bit value is >= CameraResponse::kClippedFrom
  double to_scene_linear = 0;    // 1 / (exposure_s * total gain): linear [0, 1] times this
  // Scene-linear value of a full-scale (clipped) pixel: what a clipped pixel is a lower bound of.
  double clip_level() const { return to_scene_linear; }
  const float* at(int x, int y) const {
    return &rgb[(size_t(y - rect.y0) * size_t(rect.width) + size_t(x - rect.x0)) * 3];
  }
  bool clipped_at(int x, int y) const {
    return clipped[size_t(y - rect.y0) * size_t(rect.width) + size_t(x - rect.x0)] != 0;
  }
};

// Decodes `rect` (clipped to the image) of any supported format. Only the rectangle is converted
// (widened to the format's chroma alignment), through the same BT.601 path as to_rgb24. False when
// the frame, the rectangle or the exposure metadata (exposure_ns > 0, gain > 0) is unusable.
// Bayer frames are linear already: the whole frame is developed (core/image/bayer.h, defaults) and
// the rect's values taken without the response curve; clipped at 0.98 of the white level.
// Never throws; reuses out's buffers.
bool decode_linear_patch(const Frame& frame, const ImageRect& rect, const CameraResponse& response,
                         LinearPatch& out);

// One pixel of a frame, decoded as decode_linear_patch decodes it.
struct LinearPixel {
  int x = 0, y = 0;  // image pixel, inside the frame
  float rgb[3] = {0, 0, 0};
  bool clipped = false;
};

// Decodes scattered pixels (their x and y filled in) to exactly what decode_linear_patch gives
// for them, at the cost of the pixels alone: each converts only its own chroma block, where a
// rectangle around them all would convert every pixel between them (a ring of 96 samples on the
// ground spans most of the frame). A Bayer frame is developed whole once, as by
// decode_linear_patch. False, with `pixels` partly written, when the frame or its exposure is
// unusable or a pixel lies outside the frame. Never throws.
bool decode_linear_pixels(const Frame& frame, std::span<LinearPixel> pixels, const CameraResponse& response);

}  // namespace arpipe
