// Where in the image an object can appear: the pixel rectangle that its bounding box projects to
// through the camera model, used to skip frames with nothing in view and to limit GL work.
#include "render/projected_bounds.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "render/lens/lens_projection.h"

namespace arpipe {
namespace {

// The outline of a convex box in the image is the image of some of its edges, and a distorting
// lens bends edges; points along each edge (not just the corners) follow the bend.
constexpr int kSamplesPerEdge = 16;

}  // namespace

void append_segment_in_front(std::vector<Vec3>& points_cam, const Vec3& a, const Vec3& b, int samples) {
  // Just in front of the near plane, so that the projection stays finite.
  const double near = kNearPlaneM * (1 + 1e-9);
  const bool a_in = a[2] > near, b_in = b[2] > near;
  if (!a_in && !b_in) return;
  Vec3 from = a, to = b;
  if (!a_in) from = a + ((near - a[2]) / (b[2] - a[2])) * (b - a);
  if (!b_in) to = b + ((near - b[2]) / (a[2] - b[2])) * (a - b);
  for (int s = 0; s <= samples; ++s) points_cam.push_back(from + (double(s) / samples) * (to - from));
}

bool append_pinhole_outline(std::vector<Vec3>& points_cam, std::span<const Vec3> vertices, int samples) {
  const double near = kNearPlaneM * (1 + 1e-9);
  if (vertices.empty()) return true;
  // (A non-finite point goes the cut edges' way, as before there was an outline: sorting it here
  // would break the sort's ordering.)
  for (const Vec3& v : vertices)
    if (!(v[2] > near) || !std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return false;
  // Andrew's monotone chain on the pinhole points, carrying each one's camera-frame vertex.
  std::vector<size_t> order(vertices.size());
  std::vector<Vec2> at(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) {
    order[i] = i;
    at[i] = Vec2{vertices[i][0] / vertices[i][2], vertices[i][1] / vertices[i][2]};
  }
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return at[a] < at[b]; });
  const auto turn = [&](size_t o, size_t a, size_t b) {
    return (at[a][0] - at[o][0]) * (at[b][1] - at[o][1]) - (at[a][1] - at[o][1]) * (at[b][0] - at[o][0]);
  };
  std::vector<size_t> hull(2 * order.size());
  size_t k = 0;
  for (size_t i = 0; i < order.size(); ++i) {  // lower chain
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  for (size_t i = order.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && turn(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  hull.resize(k > 1 ? k - 1 : k);  // the last point repeats the first
  if (hull.size() == 1) {
    points_cam.push_back(vertices[hull[0]]);
    return true;
  }
  for (size_t i = 0; i < hull.size(); ++i)
    append_segment_in_front(points_cam, vertices[hull[i]], vertices[hull[(i + 1) % hull.size()]], samples);
  return true;
}

std::optional<PixelRect> projected_box_rect(const CameraModel& camera, const SE3& T_cam_object, const Bounds& box,
                                            double margin_px) {
  std::array<Vec3, 8> corners = box_corners(box);
  for (Vec3& corner : corners) corner = T_cam_object * corner;
  std::vector<Vec3> points;
  points.reserve(12 * (kSamplesPerEdge + 1));
  // In front of the near plane, the outline's edges alone (a convex box's outline is made of its
  // edges); else every edge, cut there.
  if (append_pinhole_outline(points, corners, kSamplesPerEdge))
    return projected_points_rect(camera, points, margin_px);
  for (int a = 0; a < 8; ++a)
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (a & bit) continue;  // each edge once, from the corner with the bit clear
      append_segment_in_front(points, corners[static_cast<size_t>(a)], corners[static_cast<size_t>(a | bit)],
                              kSamplesPerEdge);
    }
  return projected_points_rect(camera, points, margin_px);
}

std::optional<PixelRect> projected_points_rect(const CameraModel& camera, const std::vector<Vec3>& points_cam,
                                               double margin_px) {
  const PixelRect image = PixelRect::full(camera.width(), camera.height());
  size_t behind = 0;
  for (const Vec3& p : points_cam) behind += p[2] <= kNearPlaneM;
  if (points_cam.empty() || behind == points_cam.size()) return std::nullopt;
  if (behind > 0) return image;
  std::vector<Vec2> pixels;
  camera.project(points_cam, pixels);

  double min_u = INFINITY, min_v = INFINITY, max_u = -INFINITY, max_v = -INFINITY;
  for (const Vec2& pixel : pixels) {
    if (!std::isfinite(pixel[0]) || !std::isfinite(pixel[1])) return image;  // cannot bound it: be safe
    min_u = std::min(min_u, pixel[0]);
    max_u = std::max(max_u, pixel[0]);
    min_v = std::min(min_v, pixel[1]);
    max_v = std::max(max_v, pixel[1]);
  }
  // Pixel i spans [i - 0.5, i + 0.5] (centres at integers).
  const double left = std::floor(min_u - margin_px + 0.5), right = std::ceil(max_u + margin_px + 0.5);
  const double top = std::floor(min_v - margin_px + 0.5), bottom = std::ceil(max_v + margin_px + 0.5);
  const double x0 = std::max(left, 0.0), y0 = std::max(top, 0.0);
  const double x1 = std::min(right, double(image.width)), y1 = std::min(bottom, double(image.height));
  if (x1 <= x0 || y1 <= y0) return std::nullopt;
  return PixelRect{int(x0), int(y0), int(x1 - x0), int(y1 - y0)};
}

}  // namespace arpipe
