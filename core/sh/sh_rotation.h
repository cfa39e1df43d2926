// Rotation of real SH coefficient vectors (our convention, sh_basis.h) by a 3x3 rotation, band by
// band, with Ivanic & Ruedenberg's recurrence (J. Phys. Chem. 1996, 100, 6342; 1998 correction).
#pragma once

#include <span>
#include <vector>

#include "core/geometry/vec.h"
#include "core/sh/sh_basis.h"

namespace arpipe {

// Semantics: if g(w) = f(R^T w) (the function f turned by R), the coefficients of g are
// apply(coefficients of f). So lighting estimated in the world frame is turned into an object's
// frame with R = R_object_world = transpose(R_world_object). Band l's matrix D_l is orthogonal,
// (2l+1) x (2l+1), and D(R1 R2) = D(R1) D(R2). Band 1 is R itself with rows and columns ordered
// (y, z, x) as the basis functions y_1,-1 ~ y, y_1,0 ~ z, y_1,1 ~ x.
class ShRotation {
 public:
  // R row-major (core/geometry/vec.h), a proper rotation (orthonormal, det +1; not checked);
  // bands in [1, kMaxShBands] (std::invalid_argument otherwise).
  ShRotation(const Mat3& R, int bands);

  int bands() const { return bands_; }
  // out = D in for the first k bands, where in.size() = out.size() = k^2 with k <= bands();
  // in and out may be the same memory. Throws std::invalid_argument for other sizes.
  void apply(std::span<const double> in, std::span<double> out) const;
  // Each channel rotated; in.bands <= bands() (std::invalid_argument otherwise).
  ShRgb apply(const ShRgb& in) const;
  // Band l's matrix, row-major, (2l+1)^2 entries: row m + l (output), column n + l (input).
  const std::vector<double>& band_matrix(int l) const;

 private:
  int bands_ = 0;
  std::vector<std::vector<double>> d_;  // per band
};

}  // namespace arpipe
