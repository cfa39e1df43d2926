#include "core/track/pose_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace arpipe {
namespace {

using Matrix6 = std::array<std::array<double, 6>, 6>;

// The squared reprojection error of every point; infinity when one is at or behind the camera.
double squared_error(const SE3& T, const std::vector<Vec3>& world, const std::vector<Vec2>& normalized) {
  double sum = 0;
  for (size_t i = 0; i < world.size(); ++i) {
    const Vec3 p = T * world[i];
    if (!(p[2] > 1e-12)) return std::numeric_limits<double>::infinity();
    const double rx = p[0] / p[2] - normalized[i][0], ry = p[1] / p[2] - normalized[i][1];
    sum += rx * rx + ry * ry;
  }
  return sum;
}

// Solves m x = b for symmetric positive definite m (Cholesky); false when it is not.
bool solve6(Matrix6 m, std::array<double, 6> b, std::array<double, 6>& x) {
  for (int j = 0; j < 6; ++j) {
    double d = m[j][j];
    for (int k = 0; k < j; ++k) d -= m[j][k] * m[j][k];
    if (!(d > 0)) return false;
    m[j][j] = std::sqrt(d);
    for (int i = j + 1; i < 6; ++i) {
      double s = m[i][j];
      for (int k = 0; k < j; ++k) s -= m[i][k] * m[j][k];
      m[i][j] = s / m[j][j];
    }
  }
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < i; ++k) b[i] -= m[i][k] * b[k];
    b[i] /= m[i][i];
  }
  for (int i = 5; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < 6; ++k) s -= m[k][i] * x[k];
    x[i] = s / m[i][i];
  }
  return true;
}

}  // namespace

std::optional<SE3> refine_pose(const SE3& seed, const std::vector<Vec3>& world, const std::vector<Vec2>& normalized) {
  if (world.size() != normalized.size() || world.empty()) return std::nullopt;
  SE3 T = seed;
  double error = squared_error(T, world, normalized);
  if (!std::isfinite(error)) return std::nullopt;
  double lambda = 1e-3;
  for (int step = 0; step < 100; ++step) {
    // The normal equations of the residuals for a change T <- exp(xi) T, xi = (rho, omega): each
    // point moves by rho + omega x p.
    Matrix6 h{};
    std::array<double, 6> g{};
    for (size_t i = 0; i < world.size(); ++i) {
      const Vec3 p = T * world[i];
      const double iz = 1.0 / p[2], x = p[0] * iz, y = p[1] * iz;
      const double r[2] = {x - normalized[i][0], y - normalized[i][1]};
      // d(x/z, y/z)/dp times [I | -[p]x].
      const double j[2][6] = {{iz, 0, -x * iz, -x * p[1] * iz, p[2] * iz + x * p[0] * iz, -p[1] * iz},
                              {0, iz, -y * iz, -p[2] * iz - y * p[1] * iz, y * p[0] * iz, p[0] * iz}};
      for (int row = 0; row < 2; ++row)
        for (int a = 0; a < 6; ++a) {
          g[a] += j[row][a] * r[row];
          for (int b = 0; b <= a; ++b) h[a][b] += j[row][a] * j[row][b];
        }
    }
    for (int a = 0; a < 6; ++a)
      for (int b = a + 1; b < 6; ++b) h[a][b] = h[b][a];
    bool improved = false;
    while (lambda < 1e12) {
      Matrix6 damped = h;
      for (int a = 0; a < 6; ++a) damped[a][a] += lambda * (h[a][a] > 0 ? h[a][a] : 1.0);
      std::array<double, 6> minus_g{}, xi{};
      for (int a = 0; a < 6; ++a) minus_g[a] = -g[a];
      if (!solve6(damped, minus_g, xi)) {
        lambda *= 10;
        continue;
      }
      const SE3 trial = SE3::exp(Vec6{xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]}) * T;
      const double trial_error = squared_error(trial, world, normalized);
      if (trial_error < error) {
        T = trial;
        error = trial_error;
        lambda = std::max(lambda * 0.1, 1e-12);
        improved = true;
        const double scale = std::max(1.0, norm(T.translation()));
        double largest = 0;
        for (int a = 0; a < 3; ++a) largest = std::max({largest, std::abs(xi[a]) / scale, std::abs(xi[a + 3])});
        if (largest < 1e-12) return T.normalized();
        break;
      }
      lambda *= 10;
    }
    if (!improved) break;  // no step lowers the error: at the minimum to rounding
  }
  return T.normalized();
}

}  // namespace arpipe
