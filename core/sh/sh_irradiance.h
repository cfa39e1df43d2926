// Irradiance from radiance SH of any order (Ramamoorthi & Hanrahan 2001: convolution with the
// clamped cosine is band l times A_l), and conversion to and from the fixed-size 3-band ShRgb9.
#pragma once

#include "core/geometry/vec.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

// A_l: the clamped cosine max(0, cos theta) has zonal coefficients c_l0 = A_l sqrt((2l+1) / 4 pi).
// A_0 = pi, A_1 = 2 pi / 3, A_l = 0 for odd l > 1, and for even l >= 2
// A_l = 2 pi (-1)^(l/2 - 1) / ((l + 2)(l - 1)) * l! / (2^l ((l/2)!)^2): A_2 = pi / 4, A_4 = -pi / 24.
// 0 for l < 0.
double sh_cosine_lobe_constant(int l);
// Band l of the radiance times A_l: sh_eval of the result at a unit normal n is the irradiance
// E(n) = integral of L(w) max(0, n.w) dw of the band-limited radiance.
ShRgb sh_irradiance_coefficients(const ShRgb& radiance);
// E(n) directly (no allocation). Not clamped: ringing can make it slightly negative.
Vec3 sh_irradiance(const ShRgb& radiance, const Vec3& unit_normal);

// The first 3 bands (zero-padded when `sh` has fewer), and back (3 bands).
ShRgb9 to_sh9(const ShRgb& sh);
ShRgb from_sh9(const ShRgb9& sh);

}  // namespace arpipe
