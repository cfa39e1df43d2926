// Where on the canvas the objects' multisampled image lies (render/virtual_layer.h,
// VirtualLayer::begin_objects): a texture only a little larger than what the objects can reach,
// so that llvmpipe clears and resolves it whole: its multisampled clear and resolve cost per tile
// of the whole framebuffer, whatever the scissor (ARPIPE_GL_PASS_TIMES, render/gl/pass_times.h,
// shows each pass's share).
#pragma once

#include "core/image/pixel_rect.h"

namespace arpipe {

struct WorkArea {
  // Texel (0, 0) holds canvas pixel (x, y); the texture is width x height.
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;

  // rect (canvas pixels) in texture coordinates.
  PixelRect local(const PixelRect& rect) const { return {rect.x - x, rect.y - y, rect.width, rect.height}; }
  bool operator==(const WorkArea&) const = default;
};

// Chooses each frame's work area so that the texture keeps its size while the rectangle moves and
// changes by a few pixels (a reallocation costs more than the clear):
//   - it holds the rectangle grown by one pixel on every side;
//   - it lies within the canvas;
//   - its corner is on the canvas's grid of kAlignment unless the canvas's right or bottom edge
//     moves it, and always even (the canvas's 2x2 quads, for derivatives);
//   - its size grows in steps of kStep and shrinks only after kShrinkAfter frames in a row
//     needed less than a quarter of it.
class WorkAreaChooser {
 public:
  static constexpr int kAlignment = 32;
  static constexpr int kStep = 16;
  static constexpr int kShrinkAfter = 30;

  // An empty area (width 0) when rect lies outside the canvas.
  WorkArea choose(const PixelRect& rect, int canvas_width, int canvas_height);

 private:
  int width_ = 0;
  int height_ = 0;
  int small_frames_ = 0;
};

}  // namespace arpipe
