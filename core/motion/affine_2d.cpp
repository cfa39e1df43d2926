// 2-D affine maps and their least-squares fit to point pairs (seed 000's warps), degrading to a
// similarity or a translation when the source points are collinear or coincide.
#include "core/motion/affine_2d.h"

#include <algorithm>
#include <cmath>

namespace arpipe {
namespace {

constexpr double kCollinearRatio = 1e-6;     // smaller / larger spread of the centred sources
constexpr double kCoincidentSpreadPx2 = 1e-12;  // larger spread (mean squared length), px^2
constexpr double kSingularRatio = 1e-12;     // |det| against the square of the largest entry

bool finite(const Vec2& p) { return std::isfinite(p[0]) && std::isfinite(p[1]); }

}  // namespace

std::optional<Affine2> Affine2::inverse() const {
  const double scale = std::max({std::abs(m[0]), std::abs(m[1]), std::abs(m[3]), std::abs(m[4])});
  const double det = determinant();
  if (!(scale > 0) || !std::isfinite(det) || std::abs(det) <= kSingularRatio * scale * scale) return std::nullopt;
  const double a = m[4] / det, b = -m[1] / det, d = -m[3] / det, e = m[0] / det;
  return Affine2{{a, b, -(a * m[2] + b * m[5]), d, e, -(d * m[2] + e * m[5])}};
}

Affine2 Affine2::operator*(const Affine2& r) const {
  return Affine2{{m[0] * r.m[0] + m[1] * r.m[3], m[0] * r.m[1] + m[1] * r.m[4], m[0] * r.m[2] + m[1] * r.m[5] + m[2],
                  m[3] * r.m[0] + m[4] * r.m[3], m[3] * r.m[1] + m[4] * r.m[4], m[3] * r.m[2] + m[4] * r.m[5] + m[5]}};
}

std::optional<AffineFit> fit_affine(std::span<const Vec2> src, std::span<const Vec2> dst) {
  if (src.empty() || src.size() != dst.size()) return std::nullopt;
  const size_t n = src.size();
  Vec2 src_mean{0, 0}, dst_mean{0, 0};
  for (size_t i = 0; i < n; ++i) {
    if (!finite(src[i]) || !finite(dst[i])) return std::nullopt;
    src_mean = {src_mean[0] + src[i][0], src_mean[1] + src[i][1]};
    dst_mean = {dst_mean[0] + dst[i][0], dst_mean[1] + dst[i][1]};
  }
  src_mean = {src_mean[0] / double(n), src_mean[1] / double(n)};
  dst_mean = {dst_mean[0] / double(n), dst_mean[1] / double(n)};

  // Everything below works on centred coordinates, so large pixel offsets (1e6 px) cost no
  // precision: sxx.. is the source scatter, sxu.. the cross terms with the destinations.
  double sxx = 0, sxy = 0, syy = 0, sxu = 0, syu = 0, sxv = 0, syv = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 s = src[i] - src_mean, d = dst[i] - dst_mean;
    sxx += s[0] * s[0];
    sxy += s[0] * s[1];
    syy += s[1] * s[1];
    sxu += s[0] * d[0];
    syu += s[1] * d[0];
    sxv += s[0] * d[1];
    syv += s[1] * d[1];
  }
  // Eigenvalues of the mean scatter (px^2): the spreads along and across the points' main axis.
  const double half_sum = 0.5 * (sxx + syy) / double(n);
  const double radius = std::hypot(0.5 * (sxx - syy), sxy) / double(n);
  const double larger = half_sum + radius;
  const double smaller = std::max(half_sum - radius, 0.0);

  // Linear part [a b; d e]; the translation then maps the source mean onto the destination mean.
  double a = 1, b = 0, d = 0, e = 1;
  AffineFit fit;
  if (n == 1 || larger < kCoincidentSpreadPx2) {
    // Seed defect: Algorithm 1 has no answer for coincident points; the mean shift is the best one.
    fit.kind = AffineFitKind::Translation;
  } else if (smaller < kCollinearRatio * larger) {
    // Seed defect: Algorithm 1's 6x6 system is singular for collinear points. Along the line the
    // data fix the map (unit direction u -> w); across it, take the same rotation and scale.
    fit.kind = AffineFitKind::Similarity;
    const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
    const double ux = std::cos(angle), uy = std::sin(angle);
    const double along = sxx * ux * ux + 2 * sxy * ux * uy + syy * uy * uy;  // sum of squared projections
    const double wx = (sxu * ux + syu * uy) / along, wy = (sxv * ux + syv * uy) / along;
    // L = w u^T + R90(w) R90(u)^T with R90(x, y) = (-y, x).
    a = wx * ux + wy * uy;
    b = wx * uy - wy * ux;
    d = wy * ux - wx * uy;
    e = wy * uy + wx * ux;
  } else {
    // Normal equations per output row: [sxx sxy; sxy syy] [a; b] = [sxu; syu], likewise d, e.
    fit.kind = AffineFitKind::Full;
    const double det = sxx * syy - sxy * sxy;
    a = (syy * sxu - sxy * syu) / det;
    b = (sxx * syu - sxy * sxu) / det;
    d = (syy * sxv - sxy * syv) / det;
    e = (sxx * syv - sxy * sxv) / det;
  }
  fit.map = Affine2{{a, b, dst_mean[0] - (a * src_mean[0] + b * src_mean[1]), d, e,
                     dst_mean[1] - (d * src_mean[0] + e * src_mean[1])}};

  double squared = 0;  // residuals on centred coordinates too, for the same reason
  for (size_t i = 0; i < n; ++i) {
    const Vec2 s = src[i] - src_mean, t = dst[i] - dst_mean;
    const double rx = t[0] - (a * s[0] + b * s[1]), ry = t[1] - (d * s[0] + e * s[1]);
    squared += rx * rx + ry * ry;
  }
  fit.rms_residual_px = std::sqrt(squared / double(n));
  return fit;
}

}  // namespace arpipe
