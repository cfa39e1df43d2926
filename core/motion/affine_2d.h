// A 2-D affine map of image points, x' = A x + b, and its fit to point correspondences: the warps
// that turn seed 000's two rendered intraframes into the other blur samples.
#pragma once

#include <optional>
#include <span>

#include "core/geometry/vec.h"

namespace arpipe {

struct Affine2 {
  // Row-major [a b c; d e f]: x' = a x + b y + c, y' = d x + e y + f.
  std::array<double, 6> m{1, 0, 0, 0, 1, 0};

  static Affine2 identity() { return {}; }
  static Affine2 translation(const Vec2& t) { return {{1, 0, t[0], 0, 1, t[1]}}; }
  Vec2 apply(const Vec2& p) const { return {m[0] * p[0] + m[1] * p[1] + m[2], m[3] * p[0] + m[4] * p[1] + m[5]}; }
  double determinant() const { return m[0] * m[4] - m[1] * m[3]; }
  // The inverse map; nullopt when the linear part is singular (|det| below 1e-12 of its scale).
  std::optional<Affine2> inverse() const;
  Affine2 operator*(const Affine2& rhs) const;  // (this * rhs).apply(p) == apply(rhs.apply(p))
};

// How an affine fit was determined, from the spread of the source points.
enum class AffineFitKind {
  Full,         // at least 3 points not on one line: least squares over all of them
  Similarity,   // the points lie on one line: rotation, uniform scale and translation along it
  Translation,  // the points coincide (or only one is given): the mean displacement
};

struct AffineFit {
  Affine2 map;
  AffineFitKind kind = AffineFitKind::Full;
  double rms_residual_px = 0;  // of the fitted map over the given pairs
};

// The affine map taking each src[i] to dst[i], in the least-squares sense over all pairs (the
// seed's Algorithm 1 takes exactly 3 and inverts a 6x6 matrix, which fails for collinear points;
// this uses every pair, solved on centred coordinates, and degrades as AffineFitKind says instead
// of failing). Collinear means the smaller spread of the centred source points is below
// 1e-6 of the larger (squared lengths); coincident means the larger is below 1e-12 px^2.
// nullopt only for empty or mismatched spans, or non-finite input.
std::optional<AffineFit> fit_affine(std::span<const Vec2> src, std::span<const Vec2> dst);

}  // namespace arpipe
