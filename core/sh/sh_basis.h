// Real spherical harmonics of any order: the basis (seed 002's Legendre recurrence and
// normalisation, Green's index l(l+1)+m) and RGB coefficient vectors for radiance and irradiance.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

// The highest number of bands the library supports (coefficient counts up to kMaxShBands^2).
inline constexpr int kMaxShBands = 16;

constexpr int sh_index(int l, int m) { return l * (l + 1) + m; }
constexpr int sh_count(int bands) { return bands * bands; }
// The band l of coefficient `index` (the inverse of sh_index in l): l^2 <= index < (l + 1)^2.
constexpr int sh_band(int index) {
  int l = 0;
  while (sh_count(l + 1) <= index) ++l;
  return l;
}

// Sign convention: Green's formulas without the Condon-Shortley phase, so that every constant is
// positive as in docs/reference/rendering.md section 3 (y_1,-1 = +0.488603 y). The seed's y_lm
// (with the (-1)^m phase) equals (-1)^m times ours; any convention works as long as light and
// transfer agree.
//
// Fills out[0 .. bands^2) with y_i(dir) for a unit direction (x, y, z), theta from +z.
// bands in [1, kMaxShBands]; out.size() >= bands^2 (std::invalid_argument otherwise).
// Polynomial in (x, y, z) (no angles, exact at the poles; a non-unit input is not normalised).
// The span version allocates nothing: about 20 ns for 3 bands, 50 ns for 7, 180 ns for 16 (-O2,
// the development machine).
void sh_basis(int bands, const Vec3& unit_dir, std::span<double> out);
std::vector<double> sh_basis(int bands, const Vec3& unit_dir);

// One RGB coefficient vector (radiance, irradiance or anything else projected on the basis).
struct ShRgb {
  int bands = 0;
  std::vector<Vec3> c;  // bands^2 entries, index l(l+1)+m

  ShRgb() = default;
  explicit ShRgb(int band_count) : bands(band_count), c(size_t(sh_count(band_count)), Vec3{0, 0, 0}) {}
  size_t size() const { return c.size(); }
};

// The band-limited reconstruction sum_i c_i y_i(dir).
Vec3 sh_eval(const ShRgb& sh, const Vec3& unit_dir);
// Adds weight * value * y_i(dir) to every coefficient (one quadrature sample of a projection).
void sh_add_sample(ShRgb& sh, const Vec3& unit_dir, const Vec3& value, double weight);
// The first min(bands, other.bands) bands of `sh`, zero-padded to `bands`.
ShRgb sh_truncated(const ShRgb& sh, int bands);

// The first 3 bands at a fixed size, no allocation: what a light estimate carries and the
// renderer's uniforms take. sh[i] = integral over directions of L(w) * y_i(w), RGB.
using ShRgb9 = std::array<Vec3, 9>;
// Adds (weight * y_i(dir)) * value to every coefficient (one quadrature sample of a projection).
void sh_add_sample(ShRgb9& sh, const Vec3& unit_dir, const Vec3& value, double weight);

}  // namespace arpipe
