#include "core/sh/sh9.h"

#include <cmath>
#include <numbers>

namespace arpipe {

Sh9 sh9_basis(const Vec3& d) {
  const double x = d[0], y = d[1], z = d[2];
  return {0.282094791773878, 0.488602511902920 * y, 0.488602511902920 * z, 0.488602511902920 * x,
          1.092548430592079 * x * y, 1.092548430592079 * y * z, 0.315391565252520 * (3 * z * z - 1),
          1.092548430592079 * x * z, 0.546274215296040 * (x * x - y * y)};
}

void sh9_add_sample(ShRgb9& sh, const Vec3& dir, const Vec3& radiance, double solid_angle) {
  const Sh9 y = sh9_basis(dir);
  for (size_t i = 0; i < 9; ++i) sh[i] = sh[i] + (y[i] * solid_angle) * radiance;
}

Vec3 sh9_eval(const ShRgb9& sh, const Vec3& dir) {
  const Sh9 y = sh9_basis(dir);
  Vec3 r{0, 0, 0};
  for (size_t i = 0; i < 9; ++i) r = r + y[i] * sh[i];
  return r;
}

double sh9_cosine_constant(int band) {
  constexpr double pi = std::numbers::pi;
  switch (band) {
    case 0: return pi;
    case 1: return 2 * pi / 3;
    case 2: return pi / 4;
  }
  return 0;
}

Vec3 sh9_irradiance(const ShRgb9& sh, const Vec3& normal) {
  const Sh9 y = sh9_basis(normal);
  Vec3 e{0, 0, 0};
  for (size_t i = 0; i < 9; ++i) {
    const int band = i == 0 ? 0 : (i < 4 ? 1 : 2);
    e = e + (sh9_cosine_constant(band) * y[i]) * sh[i];
  }
  return e;
}

ShRgb9 sh9_constant(const Vec3& radiance) {
  ShRgb9 sh{};
  // The integral of Y_0 over the sphere is 4 pi * 0.282095 = 2 sqrt(pi).
  sh[0] = (2 * std::sqrt(std::numbers::pi)) * radiance;
  return sh;
}

}  // namespace arpipe
