#include "core/probe/brightest_components.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace arpipe {

namespace {

struct Grid {
  int w = 0, h = 0;
  bool wrap_x = false;
  std::vector<double> lum;  // NaN: no sample
};

struct RawComponent {
  std::vector<int> cells;
};

// 4-connected components of cells with luminance >= threshold, largest first.
std::vector<RawComponent> components_at_max(const Grid& g, double threshold) {
  std::vector<uint8_t> seen(g.lum.size(), 0);
  std::vector<RawComponent> out;
  std::vector<int> stack;
  for (size_t start = 0; start < g.lum.size(); ++start) {
    if (seen[start] || !(g.lum[start] >= threshold)) continue;
    RawComponent comp;
    stack.assign(1, int(start));
    seen[start] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      comp.cells.push_back(i);
      const int x = i % g.w, y = i / g.w;
      const int nx[4] = {x - 1, x + 1, x, x};
      const int ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        int xx = nx[k];
        const int yy = ny[k];
        if (yy < 0 || yy >= g.h) continue;
        if (xx < 0 || xx >= g.w) {
          if (!g.wrap_x) continue;
          xx = (xx + g.w) % g.w;
        }
        const int j = yy * g.w + xx;
        if (seen[size_t(j)] || !(g.lum[size_t(j)] >= threshold)) continue;
        seen[size_t(j)] = 1;
        stack.push_back(j);
      }
    }
    out.push_back(std::move(comp));
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const RawComponent& a, const RawComponent& b) { return a.cells.size() > b.cells.size(); });
  return out;
}

double max_of(const std::vector<double>& v) {
  double m = -std::numeric_limits<double>::infinity();
  for (double x : v)
    if (x > m) m = x;  // NaN never compares greater
  return m;
}

}  // namespace

Vec3 highlight_light_direction(const ProbeSphere& sphere, const Vec3& camera_world, const Vec3& normal_world) {
  if (sphere.kind == ProbeSphere::Kind::Diffuse) return normal_world;
  const Vec3 point = sphere.center_world + sphere.radius_m * normal_world;
  return normalized(reflect(normalized(point - camera_world), normal_world));
}

BrightestComponentsResult brightest_components_image(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                            const CameraModel& model, const SE3& T_cam_world, const BrightestComponentsOptions& options) {
  BrightestComponentsResult result;
  Grid g;
  g.w = region.rect.width;
  g.h = region.rect.height;
  g.lum.assign(size_t(g.w) * size_t(g.h), std::numeric_limits<double>::quiet_NaN());
  for (const ProbeHit& h : region.hits) {
    if (!patch.rect.contains(h.x, h.y)) continue;
    const float* p = patch.at(h.x, h.y);
    g.lum[size_t(h.y - region.rect.y0) * size_t(g.w) + size_t(h.x - region.rect.x0)] = rec709_luminance(p[0], p[1], p[2]);
    ++result.samples;
  }
  if (result.samples == 0) return result;
  result.l_max = max_of(g.lum);
  const std::vector<RawComponent> comps = components_at_max(g, result.l_max - options.tolerance);
  const Mat3 R_world_cam = transpose(T_cam_world.rotation());
  for (const RawComponent& rc : comps) {
    if (int(result.components.size()) >= options.max_lights) break;
    BrightestComponent sc;
    sc.size = int(rc.cells.size());
    double sx = 0, sy = 0;
    int clipped = 0;
    for (int i : rc.cells) {
      const int x = region.rect.x0 + i % g.w, y = region.rect.y0 + i / g.w;
      sx += x;
      sy += y;
      clipped += patch.clipped_at(x, y) ? 1 : 0;
    }
    sc.centroid_px = {sx / sc.size, sy / sc.size};
    sc.clipped = 2 * clipped > sc.size;
    // The point under the centroid: its true view ray, intersected with the sphere.
    const auto ray = model.unproject(sc.centroid_px);
    if (!ray) continue;
    Vec3 point, normal;
    intersect_probe(sphere, region.camera_world, normalized(mat_mul(R_world_cam, *ray)), point, normal);
    sc.normal_world = normal;
    sc.light_world = highlight_light_direction(sphere, region.camera_world, normal);
    result.components.push_back(sc);
  }
  return result;
}

BrightestComponentsResult brightest_components_sphere(const ProbeSphere& sphere, const ProbeRegion& region, const LinearPatch& patch,
                             const CameraModel& model, const SE3& T_cam_world, const BrightestComponentsOptions& options) {
  BrightestComponentsResult result;
  Grid g;
  g.w = std::max(4, options.lattice_u);
  g.h = std::max(2, options.lattice_v);
  g.wrap_x = true;
  g.lum.assign(size_t(g.w) * size_t(g.h), std::numeric_limits<double>::quiet_NaN());
  std::vector<Vec3> normals(g.lum.size());
  thread_local std::vector<Vec3> points_cam;
  thread_local std::vector<int> cell_of;
  thread_local std::vector<Vec2> pixels;
  points_cam.clear();
  cell_of.clear();
  for (int j = 0; j < g.h; ++j) {
    const double theta = std::numbers::pi * (j + 0.5) / g.h;  // from +z (world up)
    for (int i = 0; i < g.w; ++i) {
      const double phi = 2 * std::numbers::pi * (i + 0.5) / g.w;
      const Vec3 n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      const size_t cell = size_t(j) * size_t(g.w) + size_t(i);
      normals[cell] = n;
      const Vec3 p = sphere.center_world + sphere.radius_m * n;
      // Hidden hemisphere: keep vertices that face the camera.
      if (dot(n, region.camera_world - p) <= 0) continue;
      points_cam.push_back(T_cam_world * p);
      cell_of.push_back(int(cell));
    }
  }
  model.project(points_cam, pixels);
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Vec2& px = pixels[k];
    if (!std::isfinite(px[0]) || !std::isfinite(px[1])) continue;
    const int x = int(std::lround(px[0])), y = int(std::lround(px[1]));
    // Only pixels of the analysed region: this drops the rim (mixed pixels) and what lies outside.
    if (region.hit_at(x, y) < 0 || !patch.rect.contains(x, y)) continue;
    const float* p = patch.at(x, y);
    g.lum[size_t(cell_of[k])] = rec709_luminance(p[0], p[1], p[2]);
    ++result.samples;
  }
  if (result.samples == 0) return result;
  result.l_max = max_of(g.lum);
  const std::vector<RawComponent> comps = components_at_max(g, result.l_max - options.tolerance);
  for (const RawComponent& rc : comps) {
    if (int(result.components.size()) >= options.max_lights) break;
    BrightestComponent sc;
    sc.size = int(rc.cells.size());
    // Averaging 3D unit vectors instead of raw (u, v): no seam or pole trouble.
    Vec3 sum{0, 0, 0};
    for (int c : rc.cells) sum = sum + normals[size_t(c)];
    if (!(norm(sum) > 0)) continue;
    sc.normal_world = normalized(sum);
    const Vec3 p_cam = T_cam_world * (sphere.center_world + sphere.radius_m * sc.normal_world);
    if (const auto px = model.project(p_cam)) {
      sc.centroid_px = *px;
      const int x = int(std::lround((*px)[0])), y = int(std::lround((*px)[1]));
      sc.clipped = patch.rect.contains(x, y) && patch.clipped_at(x, y);
    }
    sc.light_world = highlight_light_direction(sphere, region.camera_world, sc.normal_world);
    result.components.push_back(sc);
  }
  return result;
}

}  // namespace arpipe
