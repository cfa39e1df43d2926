// Closed forms the PRT tests compare the bake with: the clamped-cosine SH factors A_l and the
// cosine-weighted view factor from a point to a polygon (Lambert's contour formula).
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "core/geometry/vec.h"
#include "core/scene/mesh.h"
#include "render/prt/prt_transfer.h"

namespace arpipe::prt_test {

// Ramamoorthi-Hanrahan's A_l for l <= 2: the cosine lobe's SH convolution factors.
inline double cosine_lobe_factor(int l) {
  constexpr double pi = std::numbers::pi;
  return l == 0 ? pi : l == 1 ? 2 * pi / 3 : l == 2 ? pi / 4 : 0.0;
}

// The view factor from a differential area at p with unit normal n to a planar polygon that lies
// wholly on the side n points to: F = 1/(2 pi) |sum_k angle(r_k, r_k+1) n . unit(r_k x r_k+1)|
// (Lambert 1760; Arvo 1995 eq. 2), r_k = q_k - p. F times pi is the polygon's cosine-weighted
// solid angle seen from p.
inline double polygon_view_factor(const Vec3& p, const Vec3& n, const std::vector<Vec3>& polygon) {
  double sum = 0;
  for (size_t k = 0; k < polygon.size(); ++k) {
    const Vec3 a = normalized(polygon[k] - p), b = normalized(polygon[(k + 1) % polygon.size()] - p);
    const Vec3 c = cross(a, b);
    const double s = norm(c);
    if (s == 0) continue;
    sum += std::atan2(s, dot(a, b)) * dot(n, (1.0 / s) * c);
  }
  return std::abs(sum) / (2 * std::numbers::pi);
}

// The standard view factor from a differential area to a parallel a x b rectangle at distance c
// whose corner lies on the area's normal (e.g. Howell's catalogue, configuration B-3):
// F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))], X = a/c, Y = b/c.
inline double parallel_rectangle_corner_view_factor(double a, double b, double c) {
  const double X = a / c, Y = b / c;
  return (X / std::sqrt(1 + X * X) * std::atan(Y / std::sqrt(1 + X * X)) +
          Y / std::sqrt(1 + Y * Y) * std::atan(X / std::sqrt(1 + Y * Y))) /
         (2 * std::numbers::pi);
}

inline Vec3 vertex_position(const Mesh& mesh, size_t v) {
  return {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
}
inline Vec3 vertex_normal(const Mesh& mesh, size_t v) {
  return {mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]};
}

// The vertex nearest to `where` with a normal close to `normal`.
inline size_t find_vertex(const Mesh& mesh, const Vec3& where, const Vec3& normal) {
  size_t best = 0;
  double best_distance = INFINITY;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (dot(vertex_normal(mesh, v), normal) < 0.99) continue;
    const double d = norm(vertex_position(mesh, v) - where);
    if (d < best_distance) best_distance = d, best = v;
  }
  return best;
}

inline double mesh_diagonal(const Mesh& mesh) {
  const Bounds b = mesh.bounds();
  return norm(b.max - b.min);
}

}  // namespace arpipe::prt_test
