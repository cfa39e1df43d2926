#include "render/work_area.h"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace arpipe {
namespace {

int floor_to(int value, int step) { return value >= 0 ? value / step * step : -((-value + step - 1) / step) * step; }
int ceil_to(int value, int step) { return floor_to(value + step - 1, step); }

// Where along one axis: the start and size for a size that holds [need0, need1) within
// [0, canvas). The start stays even, as the canvas's 2x2 pixel quads (derivatives pair pixels from
// an even row and column): against an odd canvas edge the size grows by one instead.
std::pair<int, int> place(int need0, int size, int canvas) {
  const int start = std::clamp(floor_to(need0, WorkAreaChooser::kAlignment), 0, canvas - size);
  if (start % 2 == 0) return {start, size};
  return {start - 1, size + 1};
}

}  // namespace

WorkArea WorkAreaChooser::choose(const PixelRect& rect, int canvas_width, int canvas_height) {
  const PixelRect need = PixelRect{rect.x - 1, rect.y - 1, rect.width + 2, rect.height + 2}.intersected(
      PixelRect::full(canvas_width, canvas_height));
  if (rect.empty() || need.empty()) return {};
  // A size fits when the aligned start still reaches past the far side.
  const auto fits = [](int size, int need_size) { return size >= need_size + kAlignment - 1; };
  const auto grown = [](int need_size, int canvas) { return std::min(ceil_to(need_size + kAlignment, kStep), canvas); };
  const bool too_small = !(fits(width_, need.width) || width_ == canvas_width) ||
                         !(fits(height_, need.height) || height_ == canvas_height) || width_ > canvas_width ||
                         height_ > canvas_height;
  const bool far_too_big = 4 * (int64_t(grown(need.width, canvas_width)) * grown(need.height, canvas_height)) <
                           int64_t(width_) * height_;
  small_frames_ = far_too_big ? small_frames_ + 1 : 0;
  if (too_small || small_frames_ > kShrinkAfter) {
    width_ = grown(need.width, canvas_width);
    height_ = grown(need.height, canvas_height);
    small_frames_ = 0;
  }
  const auto [x, width] = place(need.x, width_, canvas_width);
  const auto [y, height] = place(need.y, height_, canvas_height);
  return {x, y, width, height};
}

}  // namespace arpipe
