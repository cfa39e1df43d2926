// An axis-aligned rectangle of whole pixels in image coordinates (x right, y down): the region of
// the frame that the virtual layer covers and to which GL work and readback are restricted, or the
// window the tag detector searches.
#pragma once

#include <algorithm>
#include <vector>

namespace arpipe {

struct PixelRect {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;

  bool empty() const { return width <= 0 || height <= 0; }
  int right() const { return x + width; }   // one past the last column
  int bottom() const { return y + height; }  // one past the last row
  bool contains(int px, int py) const { return px >= x && px < right() && py >= y && py < bottom(); }

  static PixelRect full(int width, int height) { return {0, 0, width, height}; }
  // Smallest rectangle holding both; an empty one adds nothing.
  PixelRect united(const PixelRect& other) const {
    if (empty()) return other;
    if (other.empty()) return *this;
    const int left = std::min(x, other.x), top = std::min(y, other.y);
    return {left, top, std::max(right(), other.right()) - left, std::max(bottom(), other.bottom()) - top};
  }
  // The rectangle both cover; empty when they do not meet.
  PixelRect intersected(const PixelRect& other) const {
    const int left = std::max(x, other.x), top = std::max(y, other.y);
    const int r = std::min(right(), other.right()), b = std::min(bottom(), other.bottom());
    if (r <= left || b <= top) return {};
    return {left, top, r - left, b - top};
  }
  bool operator==(const PixelRect&) const = default;
};

// The rectangles with every two that overlap replaced by the smallest one holding both, until no
// two overlap (so that drawing into each covers no pixel twice); empty ones dropped.
inline std::vector<PixelRect> disjoint_rects(std::vector<PixelRect> rects) {
  std::erase_if(rects, [](const PixelRect& r) { return r.empty(); });
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < rects.size() && !merged; ++i)
      for (size_t j = i + 1; j < rects.size() && !merged; ++j)
        if (!rects[i].intersected(rects[j]).empty()) {
          rects[i] = rects[i].united(rects[j]);
          rects.erase(rects.begin() + static_cast<long>(j));
          merged = true;
        }
  }
  return rects;
}

}  // namespace arpipe
