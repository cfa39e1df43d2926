#include "core/image/image_motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace arpipe {
namespace {

constexpr int kParameters = 8;  // affine 6 (u = a0 + a1 x + a2 y, v = a3 + a4 x + a5 y), gain, offset
using Vector = std::array<double, kParameters>;
using Matrix = std::array<std::array<double, kParameters>, kParameters>;

// Solves M x = b for symmetric positive definite M (Cholesky); false when M is not.
bool solve_spd(Matrix m, Vector b, Vector& x) {
  for (int j = 0; j < kParameters; ++j) {
    double d = m[j][j];
    for (int k = 0; k < j; ++k) d -= m[j][k] * m[j][k];
    if (!(d > 1e-9 * std::max(1.0, std::abs(m[j][j])))) return false;
    m[j][j] = std::sqrt(d);
    for (int i = j + 1; i < kParameters; ++i) {
      double s = m[i][j];
      for (int k = 0; k < j; ++k) s -= m[i][k] * m[j][k];
      m[i][j] = s / m[j][j];
    }
  }
  for (int i = 0; i < kParameters; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= m[i][k] * b[k];
    b[i] = s / m[i][i];
  }
  for (int i = kParameters - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < kParameters; ++k) s -= m[k][i] * x[k];
    x[i] = s / m[i][i];
  }
  return true;
}

// The patch smoothed by [1 2 1] / 4 each way (edges repeated). A camera's edges are about a
// pixel sharp, and central differences across such an edge misread its slope by a third, one way
// or the other depending on where the edge falls between pixels; smoothed, they read it right.
void smooth(const uint8_t* image, size_t stride, int width, int height, std::vector<float>& out,
            std::vector<float>& across) {
  across.resize(size_t(width) * size_t(height));
  out.resize(across.size());
  for (int y = 0; y < height; ++y) {
    const uint8_t* row = image + size_t(y) * stride;
    float* to = across.data() + size_t(y) * size_t(width);
    for (int x = 0; x < width; ++x)
      to[x] = 0.25f * (float(row[std::max(x - 1, 0)]) + 2.0f * float(row[x]) + float(row[std::min(x + 1, width - 1)]));
  }
  for (int y = 0; y < height; ++y) {
    const float* up = across.data() + size_t(std::max(y - 1, 0)) * size_t(width);
    const float* middle = across.data() + size_t(y) * size_t(width);
    const float* down = across.data() + size_t(std::min(y + 1, height - 1)) * size_t(width);
    float* to = out.data() + size_t(y) * size_t(width);
    for (int x = 0; x < width; ++x) to[x] = 0.25f * (up[x] + 2.0f * middle[x] + down[x]);
  }
}

}  // namespace

SmoothedPatch smoothed_patch(const uint8_t* image, size_t stride, int width, int height) {
  SmoothedPatch out;
  if (!image || width < 8 || height < 8) return out;
  std::vector<float> across;
  smooth(image, stride, width, height, out.pixels, across);
  out.width = width;
  out.height = height;
  return out;
}

std::optional<PatchMotion> patch_motion(const uint8_t* reference, size_t reference_stride, const uint8_t* current,
                                        size_t current_stride, int width, int height) {
  if (!reference || !current || width < 8 || height < 8) return std::nullopt;
  return patch_motion(smoothed_patch(reference, reference_stride, width, height), current, current_stride);
}

std::optional<PatchMotion> patch_motion(const SmoothedPatch& reference, const uint8_t* current, size_t current_stride) {
  const int width = reference.width, height = reference.height;
  if (!current || width < 8 || height < 8 || reference.pixels.size() != size_t(width) * size_t(height))
    return std::nullopt;
  // Scratch kept per thread: a tracker calls this every frame.
  thread_local std::vector<float> cur, across;
  const std::vector<float>& ref = reference.pixels;
  smooth(current, current_stride, width, height, cur, across);
  const size_t stride = size_t(width);
  // Every other pixel each way: a quarter of the work, and still thousands of edge pixels on a tag.
  constexpr int kStep = 2;
  // Coordinates from the patch's centre, in units of its half size, keep the system well scaled.
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  const float scale = float(1.0 / std::max(cx, cy));
  // The model: current(x) = (1 + gain) reference(x - d(x)) + offset, linearised:
  // current - reference = -g . d(x) + gain * reference + offset.
  const auto row_of = [&](int x, int y, std::array<float, kParameters>& j, float& e) {
    const float* r = ref.data() + size_t(y) * stride + size_t(x);
    const float gx = 0.5f * (r[1] - r[-1]);
    const float gy = 0.5f * (r[stride] - *(r - stride));
    const float px = float(x - cx) * scale, py = float(y - cy) * scale;
    j = {-gx, -gx * px, -gx * py, -gy, -gy * px, -gy * py, *r, 1.0f};
    e = cur[size_t(y) * stride + size_t(x)] - *r;
    return gx * gx + gy * gy;
  };
  // Sums per row in float (at most a few hundred terms), then in double.
  Matrix normal{};
  Vector right{};
  double gradient_energy = 0;
  int samples = 0;
  std::array<float, kParameters> j{};
  float e = 0;
  for (int y = 1; y + 1 < height; y += kStep) {
    std::array<std::array<float, kParameters>, kParameters> row_normal{};
    std::array<float, kParameters> row_right{};
    float row_energy = 0;
    for (int x = 1; x + 1 < width; x += kStep, ++samples) {
      row_energy += row_of(x, y, j, e);
      // The whole square, though only its lower half is read: eight independent sums a row, which
      // the compiler turns into vector instructions (each sum still adds the same terms in the
      // same order, so the result is the same to the bit).
      for (int a = 0; a < kParameters; ++a) {
        row_right[a] += j[a] * e;
        for (int b = 0; b < kParameters; ++b) row_normal[a][b] += j[a] * j[b];
      }
    }
    gradient_energy += row_energy;
    for (int a = 0; a < kParameters; ++a) {
      right[a] += row_right[a];
      for (int b = 0; b <= a; ++b) normal[a][b] += row_normal[a][b];
    }
  }
  // Too little texture: a flat patch says nothing about motion.
  if (samples == 0 || gradient_energy < 1.25 * samples) return std::nullopt;
  for (int a = 0; a < kParameters; ++a)
    for (int b = a + 1; b < kParameters; ++b) normal[a][b] = normal[b][a];
  Vector p{};
  if (!solve_spd(normal, right, p)) return std::nullopt;

  PatchMotion motion;
  motion.gain = p[6];
  motion.offset = p[7];
  for (const double px : {-cx * scale, cx * scale})
    for (const double py : {-cy * scale, cy * scale}) {
      const double u = p[0] + p[1] * px + p[2] * py, v = p[3] + p[4] * px + p[5] * py;
      motion.max_corner_px = std::max(motion.max_corner_px, std::hypot(u, v));
    }
  // What the fit leaves: sensor noise, or something it cannot explain. The noise level comes from
  // the residuals' median absolute deviation (a histogram of whole levels), so a noisier sensor is
  // not mistaken for a change.
  std::array<float, kParameters> pf{};
  for (int a = 0; a < kParameters; ++a) pf[a] = float(p[a]);
  std::array<int, 257> histogram{};
  for (int y = 1; y + 1 < height; y += kStep)
    for (int x = 1; x + 1 < width; x += kStep) {
      row_of(x, y, j, e);
      float model = 0;
      for (int a = 0; a < kParameters; ++a) model += j[a] * pf[a];
      ++histogram[size_t(std::min(256.0f, std::abs(e - model) + 0.5f))];
    }
  int below = 0, median = 0;
  while (median < 256 && (below += histogram[size_t(median)]) * 2 < samples) ++median;
  const double noise = 1.4826 * median;
  const int far = int(std::ceil(std::max(12.0, 5.0 * noise)));
  int outliers = 0;
  for (int level = far + 1; level <= 256; ++level) outliers += histogram[size_t(level)];
  motion.outlier_fraction = double(outliers) / samples;
  return motion;
}

}  // namespace arpipe
