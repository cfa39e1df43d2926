#include "core/sh/sh_window.h"

#include <cmath>
#include <numbers>

namespace arpipe {

double sh_window_factor(ShWindow window, int l, int bands) {
  if (l < 0 || l >= bands) return 0;
  if (l == 0) return 1;
  const double x = std::numbers::pi * l / bands;
  switch (window) {
    case ShWindow::None: return 1;
    case ShWindow::Hanning: return (1 + std::cos(x)) / 2;
    case ShWindow::Lanczos: return std::sin(x) / x;
  }
  return 1;
}

void apply_sh_window(ShRgb& sh, ShWindow window) {
  for (int l = 0; l < sh.bands; ++l) {
    const double h = sh_window_factor(window, l, sh.bands);
    for (int m = -l; m <= l; ++m) {
      Vec3& c = sh.c[size_t(sh_index(l, m))];
      c = h * c;
    }
  }
}

}  // namespace arpipe
