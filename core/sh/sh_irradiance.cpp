#include "core/sh/sh_irradiance.h"

#include <cmath>
#include <numbers>

namespace arpipe {

double sh_cosine_lobe_constant(int l) {
  constexpr double pi = std::numbers::pi;
  if (l < 0) return 0;
  if (l == 0) return pi;
  if (l == 1) return 2 * pi / 3;
  if (l % 2 == 1) return 0;
  // l! / (2^l ((l/2)!)^2) = C(l, l/2) / 2^l = prod_{k=1}^{h} (h + k) / (4 k): every factor is
  // below 1, so no overflow and ~l ulp of error at any l.
  const int h = l / 2;
  double binom = 1;
  for (int k = 1; k <= h; ++k) binom *= double(h + k) / (4.0 * k);
  const double sign = (h - 1) % 2 == 0 ? 1.0 : -1.0;
  return 2 * pi * sign / (double(l + 2) * (l - 1)) * binom;
}

ShRgb sh_irradiance_coefficients(const ShRgb& radiance) {
  ShRgb e = radiance;
  for (int l = 0; l < e.bands; ++l) {
    const double a = sh_cosine_lobe_constant(l);
    for (int m = -l; m <= l; ++m) {
      Vec3& c = e.c[size_t(sh_index(l, m))];
      c = a * c;
    }
  }
  return e;
}

Vec3 sh_irradiance(const ShRgb& radiance, const Vec3& unit_normal) {
  return sh_eval(sh_irradiance_coefficients(radiance), unit_normal);
}

ShRgb9 to_sh9(const ShRgb& sh) {
  ShRgb9 r{};
  for (size_t i = 0; i < 9 && i < sh.c.size(); ++i) r[i] = sh.c[i];
  return r;
}

ShRgb from_sh9(const ShRgb9& sh) {
  ShRgb r(3);
  for (size_t i = 0; i < 9; ++i) r.c[i] = sh[i];
  return r;
}

}  // namespace arpipe
