#include "core/probe/probe_sphere.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace arpipe {

void PixelRayCache::prepare(const CameraModel& model, const ImageRect& rect) {
  std::vector<double> key = model.intrinsics();
  key.push_back(model.width());
  key.push_back(model.height());
  if (key != key_) {
    key_ = std::move(key);
    width_ = model.width();
    height_ = model.height();
    rays_.assign(size_t(width_) * size_t(height_) * 3, std::numeric_limits<float>::quiet_NaN());
  }
  thread_local std::vector<Vec2> pixels;
  thread_local std::vector<Vec3> out;
  pixels.clear();
  for (int y = std::max(0, rect.y0); y < std::min(height_, rect.y0 + rect.height); ++y)
    for (int x = std::max(0, rect.x0); x < std::min(width_, rect.x0 + rect.width); ++x)
      if (std::isnan(ray(x, y)[0])) pixels.push_back({double(x), double(y)});
  if (pixels.empty()) return;
  model.unproject(pixels, out);
  for (size_t i = 0; i < pixels.size(); ++i) {
    float* r = &rays_[(size_t(pixels[i][1]) * size_t(width_) + size_t(pixels[i][0])) * 3];
    const Vec3& v = out[i];
    const double n = norm(v);
    if (!(n > 0) || !std::isfinite(n)) {
      r[0] = r[1] = r[2] = 0;
      continue;
    }
    for (int k = 0; k < 3; ++k) r[k] = float(v[size_t(k)] / n);
  }
}

bool intersect_probe(const ProbeSphere& s, const Vec3& cam, const Vec3& v, Vec3& point, Vec3& normal) {
  const Vec3 oc = s.center_world - cam;
  const double tc = dot(oc, v);
  const Vec3 closest = cam + tc * v;
  const double b2 = dot(closest - s.center_world, closest - s.center_world);
  const double r2 = s.radius_m * s.radius_m;
  if (b2 >= r2 || tc <= 0) {
    const Vec3 d = closest - s.center_world;
    normal = norm(d) > 0 ? normalized(d) : Vec3{0, 0, 1};
    point = s.center_world + s.radius_m * normal;
    return false;
  }
  point = cam + (tc - std::sqrt(r2 - b2)) * v;
  normal = (1.0 / s.radius_m) * (point - s.center_world);
  return true;
}

bool compute_probe_region(const ProbeSphere& s, const CameraModel& model, const SE3& T_cam_world,
                          PixelRayCache& rays, ProbeRegion& out) {
  out.hits.clear();
  out.index.clear();
  out.rect = {};
  out.rim_in_image = 0;
  out.radius_px = 0;
  out.rim_pixels = 0;
  const SE3 T_world_cam = T_cam_world.inverse();
  out.camera_world = T_world_cam.translation();
  const Vec3 c = T_cam_world * s.center_world;  // centre in the camera frame
  const double d = norm(c), r = s.radius_m;
  // The rim (tangent cone) is in front of the camera only when the sphere's nearest point along
  // the optical axis is: all rim points have z >= c.z - r.
  out.in_front = d > r && c[2] - r > 1e-6;
  if (!out.in_front) return false;
  const auto center_px = model.project(c);
  if (!center_px) {
    out.in_front = false;
    return false;
  }
  out.center_px = *center_px;

  // Rim of the tangent cone: points on the sphere where the view ray grazes it.
  const Vec3 w = (1.0 / d) * c;
  const Vec3 a = std::abs(w[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 u = normalized(cross(w, a)), v = cross(w, u);
  const double along = -r * r / d, across = r * std::sqrt(1 - r * r / (d * d));
  double xmin = 1e30, ymin = 1e30, xmax = -1e30, ymax = -1e30, radius_sum = 0;
  int projected = 0, inside = 0;
  for (int i = 0; i < kProbeRimSamples; ++i) {
    const double t = 2 * std::numbers::pi * i / kProbeRimSamples;
    const Vec3 p = c + along * w + across * (std::cos(t) * u + std::sin(t) * v);
    const auto px = model.project(p);
    if (!px) continue;
    ++projected;
    xmin = std::min(xmin, (*px)[0]);
    xmax = std::max(xmax, (*px)[0]);
    ymin = std::min(ymin, (*px)[1]);
    ymax = std::max(ymax, (*px)[1]);
    radius_sum += norm(*px - *center_px);
    if ((*px)[0] >= -0.5 && (*px)[1] >= -0.5 && (*px)[0] <= model.width() - 0.5 && (*px)[1] <= model.height() - 0.5)
      ++inside;
  }
  if (projected < kProbeRimSamples / 2) {
    out.in_front = false;
    return false;
  }
  out.rim_in_image = double(inside) / kProbeRimSamples;
  out.radius_px = radius_sum / projected;
  // Clamped in double first: a rim far outside the image must not overflow the int conversion.
  if (!std::isfinite(xmin + xmax + ymin + ymax)) return false;
  const double img_w = model.width(), img_h = model.height();
  const int x0 = int(std::clamp(std::floor(xmin) - 1, 0.0, img_w));
  const int y0 = int(std::clamp(std::floor(ymin) - 1, 0.0, img_h));
  const int x1 = int(std::clamp(std::ceil(xmax) + 2, 0.0, img_w));
  const int y1 = int(std::clamp(std::ceil(ymax) + 2, 0.0, img_h));
  if (x1 <= x0 || y1 <= y0) return false;
  out.rect = {x0, y0, x1 - x0, y1 - y0};
  rays.prepare(model, out.rect);

  const Mat3 R_world_cam = transpose(T_cam_world.rotation());
  const double cone = std::asin(r / d);
  const double margin = kProbeRimMarginPx / (0.5 * (model.fx() + model.fy()));
  const double pixel_area = 1.0 / (model.fx() * model.fy());
  out.index.assign(size_t(out.rect.width) * size_t(out.rect.height), -1);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const float* rf = rays.ray(x, y);
      if (rf[2] == 0 && rf[0] == 0 && rf[1] == 0) continue;
      const Vec3 ray{rf[0], rf[1], rf[2]};
      const double tc = dot(ray, c);
      if (tc <= 0) continue;
      const double off = std::atan2(norm(cross(ray, c)), tc);  // angle between the ray and the centre
      if (off >= cone) continue;
      if (off > cone - margin) {
        ++out.rim_pixels;
        continue;
      }
      const double b2 = d * d - tc * tc;
      const double t = tc - std::sqrt(std::max(0.0, r * r - b2));
      const Vec3 p_cam = t * ray;
      ProbeHit h;
      h.x = x;
      h.y = y;
      h.view_world = mat_mul(R_world_cam, ray);
      h.normal_world = mat_mul(R_world_cam, (1.0 / r) * (p_cam - c));
      h.distance_m = t;
      // Pinhole approximation of the pixel's solid angle (the lens's distortion changes it by a
      // few per cent at most over a probe).
      h.pixel_solid_angle = pixel_area * ray[2] * ray[2] * ray[2];
      out.index[size_t(y - y0) * size_t(out.rect.width) + size_t(x - x0)] = int32_t(out.hits.size());
      out.hits.push_back(h);
    }
  }
  return true;
}

}  // namespace arpipe
