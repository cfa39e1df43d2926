// A mesh's silhouette seen through a camera model, as a supersampled coverage mask drawn on the
// CPU, and the silhouette edge error between two masks: the mean displacement of the edge, pixels.
#include "core/scene/silhouette_raster.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arpipe {
namespace {

// Samples this close (pixels) outside a triangle's edge still count as inside: two triangles that
// share an edge then leave no sample uncovered to rounding.
constexpr double kSilhouetteEdgeSlackPx = 1e-9;

// One bit per sample: 2^31 samples are 256 MiB a mask (a 4096 x 3000 camera at 4 x 4 is 2^27.5).
constexpr uint64_t kMaxSilhouetteSamples = uint64_t{1} << 31;

// x * samples - 0.5 .. the sample index whose centre is at pixel coordinate x.
double silhouette_sample_coordinate(double pixel, int samples) { return (pixel + 0.5) * samples - 0.5; }

}  // namespace

SilhouetteMask::SilhouetteMask(int width, int height, int samples_per_axis)
    : width_(width), height_(height), samples_(samples_per_axis) {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw std::invalid_argument(fmt::format("a silhouette mask of {} x {} pixels (1 to 16384 each way)", width, height));
  if (samples_per_axis < 1 || samples_per_axis > 16)
    throw std::invalid_argument(fmt::format("{} samples per pixel axis (1 to 16)", samples_per_axis));
  const uint64_t samples = uint64_t(width) * uint64_t(height) * uint64_t(samples_per_axis) * uint64_t(samples_per_axis);
  if (samples > kMaxSilhouetteSamples)
    throw std::invalid_argument(fmt::format("a silhouette mask of {} x {} pixels with {} x {} samples each: {} samples, "
                                            "over the limit of {} (256 MiB); use fewer samples per pixel",
                                            width, height, samples_per_axis, samples_per_axis, samples,
                                            kMaxSilhouetteSamples));
  columns_ = width * samples_per_axis;
  rows_ = height * samples_per_axis;
  words_per_row_ = (static_cast<size_t>(columns_) + 63) / 64;
  bits_.assign(words_per_row_ * static_cast<size_t>(rows_), 0);
}

void SilhouetteMask::fill_triangle(const Vec2& a, const Vec2& b, const Vec2& c) {
  for (const Vec2* p : {&a, &b, &c})
    if (!std::isfinite((*p)[0]) || !std::isfinite((*p)[1])) return;
  const double area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  if (!(std::abs(area2) > 0)) return;
  // Edge lines n . p + d >= 0 inside, n of unit length (so the slack is in pixels).
  struct Edge {
    double nx, ny, d;
  };
  std::array<Edge, 3> edges{};
  const std::array<const Vec2*, 3> corners{&a, &b, &c};
  for (size_t k = 0; k < 3; ++k) {
    const Vec2& p = *corners[k];
    const Vec2& q = *corners[(k + 1) % 3];
    double nx = -(q[1] - p[1]), ny = q[0] - p[0];
    if (area2 < 0) nx = -nx, ny = -ny;
    const double length = std::hypot(nx, ny);
    edges[k] = {nx / length, ny / length, -(nx * p[0] + ny * p[1]) / length};
  }
  const double s = samples_;
  const double min_y = std::min({a[1], b[1], c[1]}), max_y = std::max({a[1], b[1], c[1]});
  const double min_x = std::min({a[0], b[0], c[0]}), max_x = std::max({a[0], b[0], c[0]});
  const double row_first = std::max(0.0, std::ceil(silhouette_sample_coordinate(min_y - kSilhouetteEdgeSlackPx, samples_)));
  const double row_last = std::min(double(rows_ - 1), std::floor(silhouette_sample_coordinate(max_y + kSilhouetteEdgeSlackPx, samples_)));
  if (row_first > row_last) return;  // also keeps far-off coordinates out of the int conversion
  for (int row = int(row_first); row <= int(row_last); ++row) {
    const double y = (row + 0.5) / s - 0.5;
    double lo = min_x - kSilhouetteEdgeSlackPx, hi = max_x + kSilhouetteEdgeSlackPx;
    bool empty = false;
    for (const Edge& e : edges) {
      // nx * x >= -(ny * y + d) - slack
      const double bound = -(e.ny * y + e.d) - kSilhouetteEdgeSlackPx;
      if (e.nx > 1e-12) lo = std::max(lo, bound / e.nx);
      else if (e.nx < -1e-12) hi = std::min(hi, bound / e.nx);
      else if (bound > 0) empty = true;
    }
    if (empty || lo > hi) continue;
    const double first = std::max(0.0, std::ceil(silhouette_sample_coordinate(lo, samples_)));
    const double last = std::min(double(columns_ - 1), std::floor(silhouette_sample_coordinate(hi, samples_)));
    if (first > last) continue;
    uint64_t* line = bits_.data() + static_cast<size_t>(row) * words_per_row_;
    const size_t from = static_cast<size_t>(first), to = static_cast<size_t>(last) + 1;  // [from, to)
    for (size_t word = from / 64; word * 64 < to; ++word) {
      const size_t begin = std::max(from, word * 64) - word * 64, end = std::min(to, word * 64 + 64) - word * 64;
      const uint64_t high = end == 64 ? ~uint64_t{0} : (uint64_t{1} << end) - 1;
      line[word] |= high & ~((uint64_t{1} << begin) - 1);
    }
  }
}

bool SilhouetteMask::covered(int sample_x, int sample_y) const {
  if (sample_x < 0 || sample_y < 0 || sample_x >= columns_ || sample_y >= rows_) return false;
  const uint64_t word = bits_[static_cast<size_t>(sample_y) * words_per_row_ + static_cast<size_t>(sample_x) / 64];
  return (word >> (sample_x % 64)) & 1;
}

size_t SilhouetteMask::covered_samples() const {
  size_t n = 0;
  for (uint64_t word : bits_) n += static_cast<size_t>(std::popcount(word));
  return n;
}

double SilhouetteMask::area_px() const { return double(covered_samples()) / (samples_ * samples_); }

std::vector<float> SilhouetteMask::coverage() const {
  std::vector<float> out(static_cast<size_t>(width_) * static_cast<size_t>(height_), 0.0f);
  const float per_sample = 1.0f / float(samples_ * samples_);
  for (int row = 0; row < rows_; ++row) {
    const uint64_t* line = bits_.data() + static_cast<size_t>(row) * words_per_row_;
    float* pixels = out.data() + static_cast<size_t>(row / samples_) * static_cast<size_t>(width_);
    for (size_t word = 0; word < words_per_row_; ++word) {
      for (uint64_t bits = line[word]; bits != 0; bits &= bits - 1) {
        const size_t column = word * 64 + static_cast<size_t>(std::countr_zero(bits));
        pixels[column / static_cast<size_t>(samples_)] += per_sample;
      }
    }
  }
  return out;
}

double SilhouetteMask::symmetric_difference_px(const SilhouetteMask& other) const {
  if (other.width_ != width_ || other.height_ != height_ || other.samples_ != samples_)
    throw std::invalid_argument(fmt::format("silhouette masks of {} x {} pixels x {}^2 samples and {} x {} x {}^2",
                                            width_, height_, samples_, other.width_, other.height_, other.samples_));
  size_t n = 0;
  for (size_t i = 0; i < bits_.size(); ++i) n += static_cast<size_t>(std::popcount(bits_[i] ^ other.bits_[i]));
  return double(n) / (samples_ * samples_);
}

double silhouette_edge_length_px(const SilhouetteMask& mask) {
  const std::vector<float> f = mask.coverage();
  const size_t w = static_cast<size_t>(mask.width()), h = static_cast<size_t>(mask.height());
  constexpr float kLevel = 0.5f;
  double length = 0;
  for (size_t j = 0; j + 1 < h; ++j)
    for (size_t i = 0; i + 1 < w; ++i) {
      // Corners counter-clockwise from (i, j); edge k runs from corner k to corner k + 1.
      const std::array<float, 4> v{f[j * w + i], f[j * w + i + 1], f[(j + 1) * w + i + 1], f[(j + 1) * w + i]};
      const std::array<bool, 4> in{v[0] > kLevel, v[1] > kLevel, v[2] > kLevel, v[3] > kLevel};
      if (in[0] == in[1] && in[1] == in[2] && in[2] == in[3]) continue;
      static constexpr std::array<std::array<double, 2>, 4> kCorner{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
      std::array<Vec2, 4> crossing{};  // on edge k, where the coverage crosses the level
      std::array<size_t, 4> crossed{};
      size_t crossings = 0;
      for (size_t k = 0; k < 4; ++k) {
        const size_t next = (k + 1) % 4;
        if (in[k] == in[next]) continue;
        const double t = (kLevel - v[k]) / double(v[next] - v[k]);
        crossing[k] = {kCorner[k][0] + t * (kCorner[next][0] - kCorner[k][0]),
                       kCorner[k][1] + t * (kCorner[next][1] - kCorner[k][1])};
        crossed[crossings++] = k;
      }
      if (crossings == 2) {
        length += norm(crossing[crossed[0]] - crossing[crossed[1]]);
        continue;
      }
      // A saddle (corners alternate): the cell centre's side decides which two opposite corners
      // the contour cuts off, each by a segment between the crossings on its two edges.
      const bool centre_in = (v[0] + v[1] + v[2] + v[3]) / 4 > kLevel;
      for (size_t k = 0; k < 4; ++k)
        if (in[k] != centre_in) length += norm(crossing[k] - crossing[(k + 3) % 4]);
    }
  return length;
}

SilhouetteEdgeError silhouette_edge_error(const SilhouetteMask& reference, const SilhouetteMask& other) {
  SilhouetteEdgeError out;
  out.difference_px2 = reference.symmetric_difference_px(other);
  out.edge_length_px = silhouette_edge_length_px(reference);
  out.error_px = out.edge_length_px > 0 ? out.difference_px2 / out.edge_length_px : std::numeric_limits<double>::quiet_NaN();
  return out;
}

size_t draw_mesh_silhouette(const Mesh& mesh, const CameraModel& camera, const SE3& T_cam_mesh, SilhouetteMask& mask) {
  if (mask.width() != camera.width() || mask.height() != camera.height())
    throw std::invalid_argument(fmt::format("a silhouette mask of {} x {} pixels for a camera of {} x {}", mask.width(),
                                            mask.height(), camera.width(), camera.height()));
  std::vector<Vec3> points(mesh.vertex_count());
  for (size_t v = 0; v < points.size(); ++v)
    points[v] = T_cam_mesh * Vec3{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
  std::vector<Vec2> pixels;
  camera.project(points, pixels);
  size_t skipped = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (a >= pixels.size() || b >= pixels.size() || c >= pixels.size()) {
      ++skipped;
      continue;
    }
    bool projectable = true;
    for (uint32_t v : {a, b, c})
      projectable = projectable && points[v][2] > 0 && std::isfinite(pixels[v][0]) && std::isfinite(pixels[v][1]);
    if (!projectable) {
      ++skipped;
      continue;
    }
    mask.fill_triangle(pixels[a], pixels[b], pixels[c]);
  }
  return skipped;
}

}  // namespace arpipe
