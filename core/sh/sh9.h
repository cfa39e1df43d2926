// Real spherical harmonics, 3 bands (9 coefficients, index l(l+1)+m, Green's convention as in
// docs/reference: positive constants), projection helpers and Ramamoorthi-Hanrahan irradiance.
#pragma once

#include <array>

#include "core/geometry/vec.h"
#include "core/light/light_estimate.h"

namespace arpipe {

using Sh9 = std::array<double, 9>;

// Y_0..Y_8 at a unit direction: 0.282095; 0.488603 {y, z, x}; 1.092548 xy, 1.092548 yz,
// 0.315392 (3z^2 - 1), 1.092548 xz, 0.546274 (x^2 - y^2).
Sh9 sh9_basis(const Vec3& dir);
// Adds radiance * Y_i(dir) * solid_angle to sh (one quadrature sample of the projection).
void sh9_add_sample(ShRgb9& sh, const Vec3& dir, const Vec3& radiance, double solid_angle);
// Radiance SH evaluated at a direction (the band-limited reconstruction).
Vec3 sh9_eval(const ShRgb9& sh, const Vec3& dir);
// Irradiance at a surface of normal n under radiance SH: sum_i A_l(i) * L_i * Y_i(n) with
// A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (Ramamoorthi & Hanrahan 2001).
Vec3 sh9_irradiance(const ShRgb9& sh, const Vec3& normal);
// The convolution constant A_l of band l (0, 1, 2) for the clamped cosine.
double sh9_cosine_constant(int band);
// Radiance SH of a constant radiance over the whole sphere.
ShRgb9 sh9_constant(const Vec3& radiance);

}  // namespace arpipe
