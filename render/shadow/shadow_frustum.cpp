// Fits the orthographic shadow-map box (see shadow_frustum.h).
#include "render/shadow/shadow_frustum.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace arpipe {
namespace {

// An orthonormal frame whose z is the light direction; x is kept horizontal where possible so the
// map's texels line up with the ground.
Mat3 light_rotation(const Vec3& z) {
  Vec3 x = cross(Vec3{0, 0, 1}, z);
  if (norm(x) < 1e-6) x = Vec3{1, 0, 0};  // light straight overhead
  x = normalized(x);
  const Vec3 y = cross(z, x);
  return {{{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}}};
}

}  // namespace

Vec3 ShadowFrustum::map_coordinates(const Vec3& world) const {
  if (local) {
    const Vec3 l = mat_mul(R_light_world, world - light_position);
    const double s = 0.5 / (l[2] * tan_half_angle);
    return {0.5 + l[0] * s, 0.5 + l[1] * s, (l[2] - near_m) / (far_m - near_m)};
  }
  const Vec3 l = mat_mul(R_light_world, world);
  // Depth 0 at the top of the box (nearest the light).
  return {(l[0] - min[0]) / (max[0] - min[0]), (l[1] - min[1]) / (max[1] - min[1]), (max[2] - l[2]) / (max[2] - min[2])};
}

std::array<float, 4> ShadowFrustum::depth_plane() const {
  const Vec3 z{R_light_world[2][0], R_light_world[2][1], R_light_world[2][2]};
  if (local) {
    const double range = far_m - near_m;
    return {float(z[0] / range), float(z[1] / range), float(z[2] / range),
            float(-(dot(z, light_position) + near_m) / range)};
  }
  const double range = max[2] - min[2];
  return {float(-z[0] / range), float(-z[1] / range), float(-z[2] / range), float(max[2] / range)};
}

std::array<float, 16> ShadowFrustum::clip_from_world() const {
  std::array<float, 16> m{};
  if (local) {
    // clip = (l.x / tan, l.y / tan, 0, l.z) with l = R (world - position): the caster pass
    // writes its own linear depth (depth_plane), so clip z only has to stay inside [-w, w].
    const Vec3 t = mat_mul(R_light_world, light_position);
    for (size_t col = 0; col < 3; ++col) {
      m[col * 4 + 0] = float(R_light_world[0][col] / tan_half_angle);
      m[col * 4 + 1] = float(R_light_world[1][col] / tan_half_angle);
      m[col * 4 + 3] = float(R_light_world[2][col]);
    }
    m[12] = float(-t[0] / tan_half_angle);
    m[13] = float(-t[1] / tan_half_angle);
    m[15] = float(-t[2]);
    return m;
  }
  // clip = 2 * map_coordinates - 1, written as a matrix (column-major: m[col * 4 + row]).
  const double sx = 2 / (max[0] - min[0]), sy = 2 / (max[1] - min[1]), sz = -2 / (max[2] - min[2]);
  const std::array<double, 3> scale{sx, sy, sz};
  const std::array<double, 3> offset{-1 - sx * min[0], -1 - sy * min[1], -1 - sz * max[2]};
  for (size_t row = 0; row < 3; ++row) {
    for (size_t col = 0; col < 3; ++col) m[col * 4 + row] = static_cast<float>(scale[row] * R_light_world[row][col]);
    m[12 + row] = static_cast<float>(offset[row]);
  }
  m[15] = 1;
  return m;
}

bool extend_depth_over(ShadowFrustum& f, const Bounds& world_box) {
  const Mat3& R = f.R_light_world;
  const Vec3 ex{R[0][0], R[0][1], R[0][2]}, ey{R[1][0], R[1][1], R[1][2]}, l{R[2][0], R[2][1], R[2][2]};
  // In slabs of the box's height (the column leans with the light, so a tall box meets it over
  // a short stretch of each): each slab's part within the box around the column's cross-sections
  // at the slab's ends. A corner (x, y) across the light lies at x ex + y ey + t l, t chosen for
  // the height.
  constexpr int kSlabs = 8;
  const int slabs = world_box.max[2] > world_box.min[2] ? kSlabs : 1;
  bool any = false;
  for (int s = 0; s < slabs; ++s) {
    const double z0 = world_box.min[2] + (world_box.max[2] - world_box.min[2]) * s / slabs;
    const double z1 = world_box.min[2] + (world_box.max[2] - world_box.min[2]) * (s + 1) / slabs;
    Bounds column{{INFINITY, INFINITY, z0}, {-INFINITY, -INFINITY, z1}};
    for (const double z : {z0, z1})
      for (int i = 0; i < 4; ++i) {
        const double x = (i & 1) ? f.max[0] : f.min[0], y = (i & 2) ? f.max[1] : f.min[1];
        const double t = (z - x * ex[2] - y * ey[2]) / l[2];
        const Vec3 p = x * ex + y * ey + t * l;
        for (size_t k = 0; k < 2; ++k) {
          column.min[k] = std::min(column.min[k], p[k]);
          column.max[k] = std::max(column.max[k], p[k]);
        }
      }
    Bounds inside;
    bool empty = false;
    for (size_t k = 0; k < 3; ++k) {
      inside.min[k] = std::max(world_box.min[k], column.min[k]);
      inside.max[k] = std::min(world_box.max[k], column.max[k]);
      empty = empty || inside.min[k] > inside.max[k];
    }
    if (empty) continue;
    any = true;
    for (const Vec3& corner : box_corners(inside)) {
      const double depth = dot(l, corner);
      f.min[2] = std::min(f.min[2], depth);
      f.max[2] = std::max(f.max[2], depth);
    }
  }
  return any;
}

std::optional<ShadowFrustum> fit_shadow_frustum(const Vec3& towards_light, std::span<const ShadowCaster> casters,
                                                double receiver_height, double margin_m, double min_elevation_sin) {
  if (casters.empty()) return std::nullopt;
  const Vec3 l = normalized(towards_light);
  if (!(l[2] >= min_elevation_sin)) return std::nullopt;
  ShadowFrustum f;
  f.R_light_world = light_rotation(l);
  constexpr double inf = std::numeric_limits<double>::infinity();
  f.min = {inf, inf, inf};
  f.max = {-inf, -inf, -inf};
  ReceiverPatch& patch = f.receiver;
  patch.height = receiver_height;
  patch.min = {inf, inf};
  patch.max = {-inf, -inf};
  auto include_light = [&](const Vec3& world) {
    const Vec3 p = mat_mul(f.R_light_world, world);
    for (size_t k = 0; k < 3; ++k) {
      f.min[k] = std::min(f.min[k], p[k]);
      f.max[k] = std::max(f.max[k], p[k]);
    }
  };
  for (const ShadowCaster& caster : casters) {
    for (const Vec3& corner : box_corners(caster.bounds)) {
      const Vec3 world = caster.T_world_object * corner;
      include_light(world);
      // Where this corner's shadow lands on the receiver (corners below the plane land on it
      // too: their shadow is the corner's own foot).
      const double s = std::max(0.0, (world[2] - receiver_height) / l[2]);
      const Vec3 on_plane{world[0] - s * l[0], world[1] - s * l[1], receiver_height};
      for (size_t k = 0; k < 2; ++k) {
        patch.min[k] = std::min(patch.min[k], on_plane[k]);
        patch.max[k] = std::max(patch.max[k], on_plane[k]);
      }
    }
  }
  for (size_t k = 0; k < 2; ++k) {
    patch.min[k] -= margin_m;
    patch.max[k] += margin_m;
  }
  // The receiver's corners set the far end of the depth range (its x, y lie within the casters'
  // shadow, so they widen the box only by the margin).
  for (int i = 0; i < 4; ++i)
    include_light({(i & 1) ? patch.max[0] : patch.min[0], (i & 2) ? patch.max[1] : patch.min[1], receiver_height});
  // Square across the light, widened by the margin; a little depth slack keeps the extremes
  // off the clip planes.
  const double half = 0.5 * std::max(f.max[0] - f.min[0], f.max[1] - f.min[1]) + margin_m;
  for (size_t k = 0; k < 2; ++k) {
    const double centre = 0.5 * (f.min[k] + f.max[k]);
    f.min[k] = centre - half;
    f.max[k] = centre + half;
  }
  const double slack = 1e-3 * std::max(f.max[2] - f.min[2], 1e-3);
  f.min[2] -= slack;
  f.max[2] += slack;
  return f;
}

}  // namespace arpipe

namespace arpipe {

std::optional<ShadowFrustum> fit_local_shadow_frustum(const Vec3& light_position, std::span<const ShadowCaster> casters,
                                                      double receiver_height, double margin_m) {
  if (casters.empty()) return std::nullopt;
  std::vector<Vec3> corners;
  Vec3 centre{0, 0, 0};
  for (const ShadowCaster& caster : casters)
    for (const Vec3& corner : box_corners(caster.bounds)) {
      corners.push_back(caster.T_world_object * corner);
      centre = centre + corners.back();
      if (corners.back()[2] >= light_position[2] - 1e-3) return std::nullopt;
    }
  if (light_position[2] <= receiver_height) return std::nullopt;
  centre = (1.0 / double(corners.size())) * centre;
  ShadowFrustum f;
  f.local = true;
  f.light_position = light_position;
  // The axis points from the light at the casters' centre; x stays horizontal where it can.
  const Vec3 axis = normalized(centre - light_position);
  f.R_light_world = light_rotation(axis);
  ReceiverPatch& patch = f.receiver;
  patch.height = receiver_height;
  constexpr double inf = std::numeric_limits<double>::infinity();
  patch.min = {inf, inf};
  patch.max = {-inf, -inf};
  // Each corner's shadow: along the ray from the light through it, down to the receiver plane.
  for (const Vec3& corner : corners) {
    const Vec3 ray = corner - light_position;
    const double s = std::max(1.0, (receiver_height - light_position[2]) / ray[2]);
    const Vec3 on_plane = light_position + s * ray;
    for (size_t k = 0; k < 2; ++k) {
      patch.min[k] = std::min(patch.min[k], on_plane[k] - margin_m);
      patch.max[k] = std::max(patch.max[k], on_plane[k] + margin_m);
    }
  }
  std::vector<Vec3> points = corners;
  for (int i = 0; i < 4; ++i)
    points.push_back({(i & 1) ? patch.max[0] : patch.min[0], (i & 2) ? patch.max[1] : patch.min[1], receiver_height});
  double tan_max = 0;
  f.near_m = inf;
  f.far_m = 0;
  for (const Vec3& p : points) {
    const Vec3 l = mat_mul(f.R_light_world, p - light_position);
    if (l[2] <= 1e-6) return std::nullopt;  // behind the light: the cone cannot hold it
    tan_max = std::max({tan_max, std::abs(l[0]) / l[2], std::abs(l[1]) / l[2]});
    f.near_m = std::min(f.near_m, l[2]);
    f.far_m = std::max(f.far_m, l[2]);
  }
  if (tan_max > 20) return std::nullopt;  // wider than about 174 degrees
  f.tan_half_angle = tan_max * 1.01;
  const double slack = 1e-3 * (f.far_m - f.near_m) + 1e-6;
  f.near_m -= slack;
  f.far_m += slack;
  return f;
}

}  // namespace arpipe
