// CameraRayGrid: unprojection grid and its self-check.
#include "capture/sim/camera_ray_grid.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arpipe::sim {

CameraRayGrid::CameraRayGrid(const CameraModel& model, double max_error_px) {
  // A lens mrcal cannot unproject (CAHVORE) would otherwise render black frames without a word.
  if (!model.unproject(Vec2{(model.width() - 1) / 2.0, (model.height() - 1) / 2.0}))
    throw std::invalid_argument(fmt::format("the simulator cannot cast rays through a {} lens: mrcal cannot unproject it",
                                            model.lensmodel()));
  // Pixel spacing is plenty for ordinary lenses; strong fisheyes need finer grids near the edge.
  for (double spacing = 1.0;; spacing /= 2) {
    build(model, spacing);
    measured_error_px_ = check(model);
    if (measured_error_px_ <= max_error_px || spacing <= 1.0 / 8) return;
  }
}

void CameraRayGrid::build(const CameraModel& model, double spacing) {
  spacing_ = spacing;
  columns_ = int(std::ceil(model.width() / spacing)) + 1;
  rows_ = int(std::ceil(model.height() / spacing)) + 1;
  std::vector<Vec2> pixels;
  pixels.reserve(size_t(columns_) * size_t(rows_));
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < columns_; ++c) pixels.push_back({-0.5 + c * spacing, -0.5 + r * spacing});
  std::vector<Vec3> directions;
  model.unproject(pixels, directions);
  nodes_.resize(directions.size());
  for (size_t i = 0; i < directions.size(); ++i)
    nodes_[i] = {float(directions[i][0]), float(directions[i][1]), float(directions[i][2])};
}

// The largest reprojection error of the interpolated ray at cell midpoints (the worst place for
// bilinear interpolation), over a sparse sample of cells.
double CameraRayGrid::check(const CameraModel& model) const {
  double worst = 0;
  const int step = std::max(1, std::min(columns_, rows_) / 40);
  for (int r = 0; r + 1 < rows_; r += step)
    for (int c = 0; c + 1 < columns_; c += step) {
      const Vec2 pixel{-0.5 + (c + 0.5) * spacing_, -0.5 + (r + 0.5) * spacing_};
      std::array<double, 3> dir{};
      if (!ray(pixel[0], pixel[1], dir)) continue;
      const auto projected = model.project({dir[0], dir[1], dir[2]});
      if (!projected) continue;
      worst = std::max(worst, std::hypot((*projected)[0] - pixel[0], (*projected)[1] - pixel[1]));
    }
  return worst;
}

bool CameraRayGrid::ray(double x, double y, std::array<double, 3>& dir) const {
  const double gx = (x + 0.5) / spacing_, gy = (y + 0.5) / spacing_;
  const int c = std::clamp(int(std::floor(gx)), 0, columns_ - 2);
  const int r = std::clamp(int(std::floor(gy)), 0, rows_ - 2);
  const double fx = gx - c, fy = gy - r;
  const auto& n00 = nodes_[size_t(r) * columns_ + c];
  const auto& n01 = nodes_[size_t(r) * columns_ + c + 1];
  const auto& n10 = nodes_[size_t(r + 1) * columns_ + c];
  const auto& n11 = nodes_[size_t(r + 1) * columns_ + c + 1];
  double v[3];
  for (int i = 0; i < 3; ++i)
    v[i] = (1 - fy) * ((1 - fx) * n00[i] + fx * n01[i]) + fy * ((1 - fx) * n10[i] + fx * n11[i]);
  const double length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!std::isfinite(length) || length == 0) return false;
  dir = {v[0] / length, v[1] / length, v[2] / length};
  return true;
}

}  // namespace arpipe::sim
