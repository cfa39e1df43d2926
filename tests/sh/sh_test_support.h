// Shared helpers of the SH tests: rotations from axis and angle, the Gram matrix of the basis
// under a quadrature rule, and the largest deviation of a matrix from the identity.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/geometry/vec.h"
#include "core/sh/sh_basis.h"
#include "core/sh/sh_sampling.h"

namespace arpipe::sh_test {

// Rodrigues: the rotation by `angle` (radians, right-handed) about the unit `axis`.
inline Mat3 axis_angle(const Vec3& axis_in, double angle) {
  const Vec3 a = normalized(axis_in);
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  return {{{t * a[0] * a[0] + c, t * a[0] * a[1] - s * a[2], t * a[0] * a[2] + s * a[1]},
           {t * a[0] * a[1] + s * a[2], t * a[1] * a[1] + c, t * a[1] * a[2] - s * a[0]},
           {t * a[0] * a[2] - s * a[1], t * a[1] * a[2] + s * a[0], t * a[2] * a[2] + c}}};
}

// z-y-z Euler angles: Rz(alpha) Ry(beta) Rz(gamma).
inline Mat3 euler_zyz(double alpha, double beta, double gamma) {
  return mat_mul(axis_angle({0, 0, 1}, alpha), mat_mul(axis_angle({0, 1, 0}, beta), axis_angle({0, 0, 1}, gamma)));
}

// G_ij = sum_k w_k y_i(d_k) y_j(d_k), row-major n x n with n = bands^2.
inline std::vector<double> gram(const std::vector<Vec3>& dirs, const std::vector<double>& weights, int bands) {
  const size_t n = size_t(sh_count(bands));
  std::vector<double> g(n * n, 0.0), y(n);
  for (size_t k = 0; k < dirs.size(); ++k) {
    sh_basis(bands, dirs[k], y);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) g[i * n + j] += weights[k] * y[i] * y[j];
  }
  return g;
}

inline double max_deviation_from_identity(const std::vector<double>& g, size_t n) {
  double worst = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) worst = std::max(worst, std::abs(g[i * n + j] - (i == j ? 1.0 : 0.0)));
  return worst;
}

}  // namespace arpipe::sh_test
