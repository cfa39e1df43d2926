#include "core/sh/sh_rotation.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include <fmt/format.h>

namespace arpipe {
namespace {

// Band l's matrix entry (m, n), m, n in [-l, l].
inline double& at(std::vector<double>& d, int l, int m, int n) { return d[size_t((m + l) * (2 * l + 1) + (n + l))]; }
inline double at(const std::vector<double>& d, int l, int m, int n) {
  return d[size_t((m + l) * (2 * l + 1) + (n + l))];
}

// Ivanic & Ruedenberg's P function (Table 2 of the 1998 correction): built from band 1 (r1) and
// band l - 1 (prev), i in {-1, 0, 1}.
double p_fn(int i, int l, int a, int b, const std::vector<double>& r1, const std::vector<double>& prev) {
  const int lp = l - 1;
  if (b == l) return at(r1, 1, i, 1) * at(prev, lp, a, lp) - at(r1, 1, i, -1) * at(prev, lp, a, -lp);
  if (b == -l) return at(r1, 1, i, 1) * at(prev, lp, a, -lp) + at(r1, 1, i, -1) * at(prev, lp, a, lp);
  return at(r1, 1, i, 0) * at(prev, lp, a, b);
}

}  // namespace

ShRotation::ShRotation(const Mat3& R, int bands) : bands_(bands) {
  if (bands < 1 || bands > kMaxShBands)
    throw std::invalid_argument(
        fmt::format("core/sh/sh_rotation.cpp: ShRotation: bands {} outside 1..{}", bands, kMaxShBands));
  d_.resize(size_t(bands));
  d_[0] = {1.0};
  if (bands == 1) return;
  // Band 1: y_1,{-1,0,1} are sqrt(3 / 4 pi) {y, z, x} (no Condon-Shortley phase), and
  // f(R^T w) = c . P R^T w gives the coefficients P R P^T c: R with axes ordered (y, z, x).
  static constexpr std::array<int, 3> axis{1, 2, 0};
  d_[1].assign(9, 0);
  for (int m = -1; m <= 1; ++m)
    for (int n = -1; n <= 1; ++n) at(d_[1], 1, m, n) = R[size_t(axis[size_t(m + 1)])][size_t(axis[size_t(n + 1)])];
  const std::vector<double>& r1 = d_[1];
  for (int l = 2; l < bands; ++l) {
    const std::vector<double>& prev = d_[size_t(l - 1)];
    std::vector<double>& d = d_[size_t(l)];
    d.assign(size_t((2 * l + 1) * (2 * l + 1)), 0);
    for (int m = -l; m <= l; ++m)
      for (int n = -l; n <= l; ++n) {
        const int am = std::abs(m);
        const double denom = std::abs(n) == l ? double(2 * l) * (2 * l - 1) : double(l + n) * (l - n);
        const double u = std::sqrt(double(l + m) * (l - m) / denom);
        const double v = 0.5 * std::sqrt((m == 0 ? 2.0 : 1.0) * (l + am - 1) * (l + am) / denom) * (m == 0 ? -1 : 1);
        const double w = m == 0 ? 0.0 : -0.5 * std::sqrt(double(l - am - 1) * (l - am) / denom);
        double value = 0;
        if (u != 0) value += u * p_fn(0, l, m, n, r1, prev);
        if (v != 0) {
          double vv;
          if (m == 0) {
            vv = p_fn(1, l, 1, n, r1, prev) + p_fn(-1, l, -1, n, r1, prev);
          } else if (m > 0) {
            vv = p_fn(1, l, m - 1, n, r1, prev) * (m == 1 ? std::sqrt(2.0) : 1.0) -
                 (m == 1 ? 0.0 : p_fn(-1, l, -m + 1, n, r1, prev));
          } else {
            vv = (m == -1 ? 0.0 : p_fn(1, l, m + 1, n, r1, prev)) +
                 p_fn(-1, l, -m - 1, n, r1, prev) * (m == -1 ? std::sqrt(2.0) : 1.0);
          }
          value += v * vv;
        }
        if (w != 0) {
          const double ww = m > 0 ? p_fn(1, l, m + 1, n, r1, prev) + p_fn(-1, l, -m - 1, n, r1, prev)
                                  : p_fn(1, l, m - 1, n, r1, prev) - p_fn(-1, l, -m + 1, n, r1, prev);
          value += w * ww;
        }
        at(d, l, m, n) = value;
      }
  }
}

void ShRotation::apply(std::span<const double> in, std::span<double> out) const {
  int k = 0;
  while (k < bands_ && size_t((k + 1) * (k + 1)) <= in.size()) ++k;
  if (in.size() != out.size() || in.size() != size_t(k * k))
    throw std::invalid_argument(fmt::format(
        "core/sh/sh_rotation.cpp: ShRotation::apply: sizes {} -> {} (need equal, a square of at most {} bands)",
        in.size(), out.size(), bands_));
  std::array<double, 2 * kMaxShBands - 1> band;  // a copy, so that in and out may alias
  for (int l = 0; l < k; ++l) {
    const int n = 2 * l + 1;
    const size_t base = size_t(l * l);
    for (int j = 0; j < n; ++j) band[size_t(j)] = in[base + size_t(j)];
    const std::vector<double>& d = d_[size_t(l)];
    for (int i = 0; i < n; ++i) {
      double s = 0;
      for (int j = 0; j < n; ++j) s += d[size_t(i * n + j)] * band[size_t(j)];
      out[base + size_t(i)] = s;
    }
  }
}

ShRgb ShRotation::apply(const ShRgb& in) const {
  if (in.bands > bands_ || in.c.size() != size_t(sh_count(in.bands)))
    throw std::invalid_argument(fmt::format(
        "core/sh/sh_rotation.cpp: ShRotation::apply: {} bands in, the rotation has {}", in.bands, bands_));
  ShRgb out(in.bands);
  std::vector<double> a(in.c.size()), b(in.c.size());
  for (size_t ch = 0; ch < 3; ++ch) {
    for (size_t i = 0; i < a.size(); ++i) a[i] = in.c[i][ch];
    apply(a, b);
    for (size_t i = 0; i < b.size(); ++i) out.c[i][ch] = b[i];
  }
  return out;
}

const std::vector<double>& ShRotation::band_matrix(int l) const {
  if (l < 0 || l >= bands_)
    throw std::invalid_argument(
        fmt::format("core/sh/sh_rotation.cpp: ShRotation::band_matrix: band {} outside 0..{}", l, bands_ - 1));
  return d_[size_t(l)];
}

}  // namespace arpipe
