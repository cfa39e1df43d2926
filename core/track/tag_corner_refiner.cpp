// Sub-pixel refinement of a detected tag's four corners: each border edge is located from the
// linear-light intensity profile across it, and the edges are intersected undistorted.
#include "core/track/tag_corner_refiner.h"
#include "core/image/srgb.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace arpipe {
namespace {

constexpr double kSampleStepPx = 0.25;
constexpr double kMaxReachPx = 2.5;          // how far across an edge to look, at most
constexpr double kMinReachPx = 1.5;          // below this a border cell is too small to refine
constexpr double kReachPerCell = 0.4;        // stay inside the one-cell rings on both sides
constexpr double kEdgeMargin = 0.12;         // fraction of the edge skipped at each end (corners)
constexpr int kMaxPointsPerEdge = 24;
constexpr int kMinPointsPerEdge = 4;
constexpr double kMinContrast = 0.04;        // linear units: black and white must differ this much
constexpr double kMaxCornerShiftPx = 1.5;    // a refinement that moves a corner farther is refused
constexpr double kOutlierFactor = 4.0;       // edge points farther than this times the median are dropped
constexpr int kMaxProfileSamples = 2 * static_cast<int>(kMaxReachPx / kSampleStepPx) + 1;

// A straight line in normalised coordinates: points p with dot(normal, p) = offset.
struct Line {
  double nx = 0, ny = 0, offset = 0;
};

// Total-least-squares fit (the principal direction of the points).
std::optional<Line> fit_line_once(const std::vector<Vec2>& points) {
  if (points.size() < static_cast<size_t>(kMinPointsPerEdge)) return std::nullopt;
  double mx = 0, my = 0;
  for (const Vec2& p : points) mx += p[0], my += p[1];
  mx /= static_cast<double>(points.size());
  my /= static_cast<double>(points.size());
  double sxx = 0, sxy = 0, syy = 0;
  for (const Vec2& p : points) {
    const double dx = p[0] - mx, dy = p[1] - my;
    sxx += dx * dx, sxy += dx * dy, syy += dy * dy;
  }
  // Direction of largest spread: angle theta with tan(2 theta) = 2 sxy / (sxx - syy).
  const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
  const double nx = -std::sin(theta), ny = std::cos(theta);
  return Line{nx, ny, nx * mx + ny * my};
}

// A fit, then a refit without the points far from it (a finger or a glint across an edge).
std::optional<Line> fit_line(const std::vector<Vec2>& points) {
  const auto first = fit_line_once(points);
  if (!first) return std::nullopt;
  std::vector<double> residuals;
  for (const Vec2& p : points) residuals.push_back(std::abs(first->nx * p[0] + first->ny * p[1] - first->offset));
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double limit = kOutlierFactor * sorted[sorted.size() / 2];
  std::vector<Vec2> inliers;
  for (size_t i = 0; i < points.size(); ++i) {
    if (residuals[i] <= limit) inliers.push_back(points[i]);
  }
  if (inliers.size() == points.size() || inliers.size() < static_cast<size_t>(kMinPointsPerEdge)) return first;
  return fit_line_once(inliers);
}

std::optional<Vec2> intersect(const Line& a, const Line& b) {
  const double det = a.nx * b.ny - a.ny * b.nx;
  if (std::abs(det) < 1e-12) return std::nullopt;
  return Vec2{(a.offset * b.ny - a.ny * b.offset) / det, (a.nx * b.offset - a.offset * b.nx) / det};
}

class LinearImage {
 public:
  LinearImage(const uint8_t* grey, int width, int height, size_t stride, const std::array<float, 256>& linear)
      : grey_(grey), width_(width), height_(height), stride_(stride), linear_(linear) {}

  // Bilinear interpolation of linear intensity; pixel centres at integer coordinates (mrcal's).
  std::optional<double> at(double x, double y) const {
    if (!(x >= 0 && y >= 0 && x <= width_ - 1 && y <= height_ - 1)) return std::nullopt;
    const int x0 = std::min(static_cast<int>(x), width_ - 2);
    const int y0 = std::min(static_cast<int>(y), height_ - 2);
    const double fx = x - x0, fy = y - y0;
    const uint8_t* row0 = grey_ + static_cast<size_t>(y0) * stride_ + x0;
    const uint8_t* row1 = row0 + stride_;
    const double top = (1 - fx) * linear_[row0[0]] + fx * linear_[row0[1]];
    const double bottom = (1 - fx) * linear_[row1[0]] + fx * linear_[row1[1]];
    return (1 - fy) * top + fy * bottom;
  }

 private:
  const uint8_t* grey_;
  int width_, height_;
  size_t stride_;
  const std::array<float, 256>& linear_;
};

// Where, along p + s * normal for s in [-reach, reach], the edge lies: the normalised profile f
// rises from 0 (one end's level) to 1 (the other's), and a step at e has integral reach - e over the
// window. This area estimate is exact for any symmetric blur, including a pixel's own box filter,
// where a half-way crossing between interpolated samples is off by up to 0.1 px. nullopt when the
// two ends do not differ clearly.
std::optional<double> edge_offset(const LinearImage& image, const Vec2& p, const Vec2& normal, double reach) {
  const int half = static_cast<int>(reach / kSampleStepPx);
  const int count = 2 * half + 1;
  std::array<double, kMaxProfileSamples> profile{};
  for (int i = 0; i < count; ++i) {
    const double s = (i - half) * kSampleStepPx;
    const auto value = image.at(p[0] + s * normal[0], p[1] + s * normal[1]);
    if (!value) return std::nullopt;
    profile[i] = *value;
  }
  const double start_level = (profile[0] + profile[1] + profile[2]) / 3;
  const double end_level = (profile[count - 1] + profile[count - 2] + profile[count - 3]) / 3;
  if (std::abs(end_level - start_level) < kMinContrast) return std::nullopt;
  double integral = 0;  // trapezoid rule over the normalised profile
  for (int i = 0; i < count; ++i) {
    const double f = (profile[i] - start_level) / (end_level - start_level);
    integral += (i == 0 || i == count - 1) ? f / 2 : f;
  }
  integral *= kSampleStepPx;
  const double window = half * kSampleStepPx;
  const double offset = window - integral;
  if (!(std::abs(offset) < window)) return std::nullopt;
  return offset;
}

}  // namespace

TagCornerRefiner::TagCornerRefiner(PixelFormat grey_encoding) {
  const bool limited_range = grey_encoding == PixelFormat::YUYV || grey_encoding == PixelFormat::NV12;
  for (int code = 0; code < 256; ++code) {
    const double encoded = limited_range ? (code - 16) / 219.0 : code / 255.0;
    linear_[code] = static_cast<float>(srgb_decode(std::clamp(encoded, 0.0, 1.0)));
  }
}

bool TagCornerRefiner::refine(const uint8_t* grey, int width, int height, size_t stride, const CameraModel& camera,
                              int border_cells, std::array<Vec2, 4>& corners, std::array<Vec2, 4>* normalized) const {
  if (!grey || width < 2 || height < 2 || border_cells <= 0) return false;
  const LinearImage image(grey, width, height, stride, linear_);

  std::array<Line, 4> edges;  // edge k runs from corner k to corner k+1
  for (size_t k = 0; k < 4; ++k) {
    const Vec2& a = corners[k];
    const Vec2& b = corners[(k + 1) % 4];
    const Vec2 along{b[0] - a[0], b[1] - a[1]};
    const double length = norm(along);
    const double reach = std::min(kMaxReachPx, kReachPerCell * length / border_cells);
    if (reach < kMinReachPx) return false;
    const Vec2 normal{-along[1] / length, along[0] / length};
    const int points = std::clamp(static_cast<int>(length / 4), kMinPointsPerEdge, kMaxPointsPerEdge);
    std::vector<Vec2> edge_points;
    for (int j = 0; j < points; ++j) {
      const double t = kEdgeMargin + (1 - 2 * kEdgeMargin) * (j + 0.5) / points;
      const Vec2 p{a[0] + t * along[0], a[1] + t * along[1]};
      const auto s = edge_offset(image, p, normal, reach);
      if (!s) continue;
      // Straight edges of the tag are straight only after undistortion. The points lie a few
      // pixels apart: each starts from its neighbour's solution.
      const Vec2 on_edge{p[0] + *s * normal[0], p[1] + *s * normal[1]};
      const auto n = edge_points.empty() ? camera.normalize(on_edge) : camera.normalize_near(on_edge, edge_points.back());
      if (n) edge_points.push_back(*n);
    }
    const auto line = fit_line(edge_points);
    if (!line) return false;
    edges[k] = *line;
  }

  std::array<Vec2, 4> refined, undistorted;
  for (size_t k = 0; k < 4; ++k) {
    const auto corner = intersect(edges[(k + 3) % 4], edges[k]);
    if (!corner) return false;
    undistorted[k] = *corner;
    const auto pixel = camera.project(Vec3{(*corner)[0], (*corner)[1], 1.0});
    if (!pixel || norm(Vec2{(*pixel)[0] - corners[k][0], (*pixel)[1] - corners[k][1]}) > kMaxCornerShiftPx) {
      return false;
    }
    refined[k] = *pixel;
  }
  corners = refined;
  if (normalized) *normalized = undistorted;
  return true;
}

}  // namespace arpipe
