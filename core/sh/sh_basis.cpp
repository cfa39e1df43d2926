#include "core/sh/sh_basis.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

namespace arpipe {
namespace {

// Per (l, m), m >= 0: the normalisation sqrt(2) K_l^m (K_l^0 for m = 0) and the three-term
// recurrence's factors (2l - 1) / (l - m) and (l + m - 1) / (l - m), computed once: the basis
// itself then needs no division, square root or trigonometric function.
struct BasisTables {
  std::array<double, kMaxShBands * kMaxShBands> norm{};
  std::array<double, kMaxShBands * kMaxShBands> a{};
  std::array<double, kMaxShBands * kMaxShBands> b{};
  std::array<double, kMaxShBands> pmm{};  // (2m - 1)!!, exact in a double up to m = 15 (29!! < 2^53)

  BasisTables() {
    for (int l = 0; l < kMaxShBands; ++l)
      for (int m = 0; m <= l; ++m) {
        // (l - m)! / (l + m)! as a product of 2m factors of order 1/l: no overflow and ~1e-15
        // relative error even at l = 15 (30! would be 2.7e32).
        double ratio = 1;
        for (int k = l - m + 1; k <= l + m; ++k) ratio /= k;
        const double k_lm = std::sqrt((2 * l + 1) * ratio / (4 * std::numbers::pi));
        norm[size_t(l * kMaxShBands + m)] = m == 0 ? k_lm : std::numbers::sqrt2 * k_lm;
        if (l >= m + 2) {
          a[size_t(l * kMaxShBands + m)] = double(2 * l - 1) / (l - m);
          b[size_t(l * kMaxShBands + m)] = double(l + m - 1) / (l - m);
        }
      }
    double df = 1;
    for (int m = 0; m < kMaxShBands; ++m) {
      pmm[size_t(m)] = df;
      df *= 2 * m + 1;
    }
  }
};

const BasisTables& tables() {
  static const BasisTables t;
  return t;
}

}  // namespace

// Green's y_lm without the Condon-Shortley phase. With s = sin(theta) = sqrt(x^2 + y^2),
// P_l^m(z) = s^m Q_l^m(z) where Q is a polynomial (Eq. 4.14 divided by s^m: Q_m^m = (2m-1)!!,
// Q_{m+1}^m = z (2m+1) Q_m^m, then the same three-term recurrence), and s^m cos(m phi),
// s^m sin(m phi) are the real and imaginary parts of (x + i y)^m (the Chebyshev recurrence on
// (x, y)). So no angle, no atan2 and no square root: exact at the poles and cheap.
void sh_basis(int bands, const Vec3& d, std::span<double> out) {
  if (bands < 1 || bands > kMaxShBands || out.size() < size_t(sh_count(bands)))
    throw std::invalid_argument(
        fmt::format("core/sh/sh_basis.cpp: sh_basis: bands {} (need 1..{}) or output size {} too small", bands,
                    kMaxShBands, out.size()));
  const BasisTables& t = tables();
  const double x = d[0], y = d[1], z = d[2];
  double c = 1, s = 0;  // Re, Im of (x + i y)^m
  for (int m = 0; m < bands; ++m) {
    // l = m
    double q_prev2 = 0;
    double q_prev = t.pmm[size_t(m)];
    const auto store = [&](int l, double q) {
      const double n = t.norm[size_t(l * kMaxShBands + m)] * q;
      if (m == 0) {
        out[size_t(sh_index(l, 0))] = n;
      } else {
        out[size_t(sh_index(l, m))] = n * c;
        out[size_t(sh_index(l, -m))] = n * s;
      }
    };
    store(m, q_prev);
    if (m + 1 < bands) {
      q_prev2 = q_prev;
      q_prev = z * (2 * m + 1) * q_prev2;
      store(m + 1, q_prev);
    }
    for (int l = m + 2; l < bands; ++l) {
      const size_t k = size_t(l * kMaxShBands + m);
      const double q = t.a[k] * z * q_prev - t.b[k] * q_prev2;
      q_prev2 = q_prev;
      q_prev = q;
      store(l, q);
    }
    const double c_next = x * c - y * s;
    s = x * s + y * c;
    c = c_next;
  }
}

std::vector<double> sh_basis(int bands, const Vec3& unit_dir) {
  if (bands < 1 || bands > kMaxShBands)
    throw std::invalid_argument(fmt::format("core/sh/sh_basis.cpp: sh_basis: bands {} outside 1..{}", bands,
                                            kMaxShBands));
  std::vector<double> out(size_t(sh_count(bands)));
  sh_basis(bands, unit_dir, out);
  return out;
}

Vec3 sh_eval(const ShRgb& sh, const Vec3& unit_dir) {
  if (sh.bands < 1) return {0, 0, 0};
  std::array<double, kMaxShBands * kMaxShBands> y;
  sh_basis(sh.bands, unit_dir, y);
  Vec3 r{0, 0, 0};
  for (size_t i = 0; i < sh.c.size(); ++i)
    for (int k = 0; k < 3; ++k) r[size_t(k)] += y[i] * sh.c[i][size_t(k)];
  return r;
}

void sh_add_sample(ShRgb& sh, const Vec3& unit_dir, const Vec3& value, double weight) {
  if (sh.bands < 1) return;
  std::array<double, kMaxShBands * kMaxShBands> y;
  sh_basis(sh.bands, unit_dir, y);
  const Vec3 v = weight * value;
  for (size_t i = 0; i < sh.c.size(); ++i)
    for (int k = 0; k < 3; ++k) sh.c[i][size_t(k)] += y[i] * v[size_t(k)];
}

void sh_add_sample(ShRgb9& sh, const Vec3& unit_dir, const Vec3& value, double weight) {
  std::array<double, 9> y;
  sh_basis(3, unit_dir, y);
  for (size_t i = 0; i < 9; ++i) sh[i] = sh[i] + (y[i] * weight) * value;
}

ShRgb sh_truncated(const ShRgb& sh, int bands) {
  if (bands < 0 || bands > kMaxShBands)
    throw std::invalid_argument(fmt::format("core/sh/sh_basis.cpp: sh_truncated: bands {} outside 0..{}", bands,
                                            kMaxShBands));
  ShRgb r(bands);
  const size_t n = std::min(r.c.size(), sh.c.size());
  for (size_t i = 0; i < n; ++i) r.c[i] = sh.c[i];
  return r;
}

}  // namespace arpipe
