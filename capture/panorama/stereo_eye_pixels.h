// One eye's pixels out of a stereo pair's whole image (the left eye on top or on the left), for
// 8-bit pictures and float radiance alike.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace arpipe {

// The eye's width x height x 3 values (eye 0 the left, 1 the right) of a whole image of
// width x height x 3, rows top to bottom; top_bottom: the eyes stacked, else side by side.
// The caller has checked the shape (EquirectImage::shape_problem).
template <class T>
std::vector<T> stereo_eye_pixels(const std::vector<T>& whole, int width, int height, bool top_bottom, int eye) {
  const int eye_width = top_bottom ? width : width / 2, eye_height = top_bottom ? height / 2 : height;
  const size_t eye_row = size_t(eye_width) * 3, row = size_t(width) * 3;
  std::vector<T> pixels(eye_row * size_t(eye_height));
  for (int y = 0; y < eye_height; ++y) {
    const size_t from = top_bottom ? size_t(eye * eye_height + y) * row : size_t(y) * row + size_t(eye) * eye_row;
    std::copy_n(whole.data() + from, eye_row, pixels.data() + size_t(y) * eye_row);
  }
  return pixels;
}

}  // namespace arpipe
