// The X-junction model fit: I(x) = m + a * erf(d1 / s) * erf(d2 / s), d_k = n_k . (x - c), with
// n_k the unit normal of edge k at angle theta_k. Seven parameters (c, theta_1, theta_2, m, a, s),
// fitted to the window's pixels by Levenberg-Marquardt with the analytic Jacobian. The model is
// point-symmetric about c like the junction itself, so an error in its blur profile (the real one
// is a pixel's box times the optics, the sensor's gamma on top) moves both sides alike and does not
// move c: only the edges' curvature over the window could, and a lens bends a 10 px edge by
// hundredths of a pixel.
#include "calib/chessboard_corner_fit.h"

#include "core/image/srgb.h"

#include <Eigen/Dense>
#include <array>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

namespace arpipe::calib {

namespace {

constexpr double kTwoOverSqrtPi = 1.1283791670955126;

struct Pixel {
  double x, y, value;
};

struct Params {
  double cx, cy, theta1, theta2, m, a, s;
  Eigen::Matrix<double, 7, 1> vector() const { return {cx, cy, theta1, theta2, m, a, s}; }
  static Params from(const Eigen::Matrix<double, 7, 1>& v) { return {v[0], v[1], v[2], v[3], v[4], v[5], v[6]}; }
};

// Offsets of the n x n sub-samples of a pixel from its centre.
std::vector<double> subsample_offsets(int n) {
  std::vector<double> out;
  for (int i = 0; i < n; ++i) out.push_back((i + 0.5) / n - 0.5);
  return out;
}

double sum_of_squares(const std::vector<Pixel>& pixels, const Params& p, const std::vector<double>& offsets) {
  const double c1 = std::cos(p.theta1), s1 = std::sin(p.theta1), c2 = std::cos(p.theta2), s2 = std::sin(p.theta2);
  const double share = 1.0 / double(offsets.size() * offsets.size());
  double sum = 0;
  for (const Pixel& q : pixels) {
    double model = 0;
    for (double oy : offsets)
      for (double ox : offsets) {
        const double dx = q.x + ox - p.cx, dy = q.y + oy - p.cy;
        model += std::erf((c1 * dx + s1 * dy) / p.s) * std::erf((c2 * dx + s2 * dy) / p.s);
      }
    const double r = p.m + p.a * model * share - q.value;
    sum += r * r;
  }
  return sum;
}

// Normal equations J^T J and J^T r at p.
void normal_equations(const std::vector<Pixel>& pixels, const Params& p, const std::vector<double>& offsets,
                      Eigen::Matrix<double, 7, 7>& jtj, Eigen::Matrix<double, 7, 1>& jtr) {
  jtj.setZero();
  jtr.setZero();
  const double c1 = std::cos(p.theta1), s1 = std::sin(p.theta1), c2 = std::cos(p.theta2), s2 = std::sin(p.theta2);
  const double share = 1.0 / double(offsets.size() * offsets.size());
  for (const Pixel& q : pixels) {
    Eigen::Matrix<double, 7, 1> j = Eigen::Matrix<double, 7, 1>::Zero();
    double model = 0;
    for (double oy : offsets)
      for (double ox : offsets) {
        const double dx = q.x + ox - p.cx, dy = q.y + oy - p.cy;
        const double z1 = (c1 * dx + s1 * dy) / p.s, z2 = (c2 * dx + s2 * dy) / p.s;
        const double e1 = std::erf(z1), e2 = std::erf(z2);
        const double g1 = kTwoOverSqrtPi * std::exp(-z1 * z1), g2 = kTwoOverSqrtPi * std::exp(-z2 * z2);
        model += e1 * e2;
        j[0] += -p.a * (g1 * c1 * e2 + e1 * g2 * c2) / p.s;
        j[1] += -p.a * (g1 * s1 * e2 + e1 * g2 * s2) / p.s;
        j[2] += p.a * g1 * (-s1 * dx + c1 * dy) / p.s * e2;
        j[3] += p.a * e1 * g2 * (-s2 * dx + c2 * dy) / p.s;
        j[5] += e1 * e2;
        j[6] += -p.a * (g1 * z1 * e2 + e1 * g2 * z2) / p.s;
      }
    j *= share;
    j[4] = 1;
    const double r = p.m + p.a * model * share - q.value;
    jtj.selfadjointView<Eigen::Lower>().rankUpdate(j);
    jtr += j * r;
  }
  jtj = jtj.selfadjointView<Eigen::Lower>();
}

}  // namespace

std::optional<Vec2> fit_chessboard_corner(const cv::Mat& grey, const Vec2& guess, const Vec2& edge_a,
                                          const Vec2& edge_b, const CornerFitOptions& options) {
  if (grey.empty() || grey.type() != CV_8UC1 || !(options.radius_px > 1)) return std::nullopt;
  if (!std::isfinite(guess[0]) || !std::isfinite(guess[1])) return std::nullopt;
  const double radius = options.radius_px;
  const int x0 = static_cast<int>(std::floor(guess[0] - radius)), x1 = static_cast<int>(std::ceil(guess[0] + radius));
  const int y0 = static_cast<int>(std::floor(guess[1] - radius)), y1 = static_cast<int>(std::ceil(guess[1] + radius));
  if (x0 < 0 || y0 < 0 || x1 >= grey.cols || y1 >= grey.rows) return std::nullopt;

  // Light adds up over a pixel's area in linear units, not in the camera's encoded ones.
  static const std::array<double, 256> linear = [] {
    std::array<double, 256> out{};
    for (size_t i = 0; i < out.size(); ++i) out[i] = 255 * srgb_decode(double(i) / 255);
    return out;
  }();
  std::vector<Pixel> pixels;
  double lo = 255, hi = 0, mean = 0;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const double dx = x - guess[0], dy = y - guess[1];
      if (dx * dx + dy * dy > radius * radius) continue;
      const unsigned char code = grey.at<unsigned char>(y, x);
      const double v = options.srgb_encoded ? linear[code] : double(code);
      pixels.push_back({double(x), double(y), v});
      lo = std::min(lo, v), hi = std::max(hi, v), mean += v;
    }
  if (pixels.size() < 12) return std::nullopt;
  mean /= double(pixels.size());
  const std::vector<double> offsets = subsample_offsets(std::max(1, options.subsamples));

  // Start: edge k runs along edge_a or edge_b, so its normal is that direction turned by 90 degrees.
  // The sign of a says which pair of opposite quadrants is bright: take the better of the two.
  Params p{guess[0], guess[1], std::atan2(edge_a[0], -edge_a[1]), std::atan2(edge_b[0], -edge_b[1]), mean,
           (hi - lo) / 2, 0.7};
  Params flipped = p;
  flipped.a = -p.a;
  if (sum_of_squares(pixels, flipped, offsets) < sum_of_squares(pixels, p, offsets)) p = flipped;

  double cost = sum_of_squares(pixels, p, offsets);
  double lambda = 1e-3;
  Eigen::Matrix<double, 7, 7> jtj;
  Eigen::Matrix<double, 7, 1> jtr;
  bool converged = false;
  for (int iteration = 0; iteration < options.max_iterations && !converged; ++iteration) {
    normal_equations(pixels, p, offsets, jtj, jtr);
    // Retry with more damping until the step lowers the cost.
    for (int attempt = 0; attempt < 10; ++attempt) {
      Eigen::Matrix<double, 7, 7> damped = jtj;
      damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-9);
      const Eigen::Matrix<double, 7, 1> step = damped.ldlt().solve(-jtr);
      if (!step.allFinite()) return std::nullopt;
      const Params next = Params::from(p.vector() + step);
      const double next_cost = next.s > 0.02 ? sum_of_squares(pixels, next, offsets) : INFINITY;
      if (next_cost < cost) {
        converged = std::hypot(step[0], step[1]) < 1e-5 && cost - next_cost < 1e-10 * cost + 1e-12;
        p = next, cost = next_cost;
        lambda = std::max(lambda / 4, 1e-9);
        break;
      }
      lambda *= 8;
      if (attempt == 9) converged = true;  // no step lowers the cost: at the minimum to precision
    }
  }

  // A credible junction: contrast, edges at least 15 degrees apart, sharp enough, and still near
  // where it started.
  const double sin_between = std::abs(std::sin(p.theta1 - p.theta2));
  const double shift = std::hypot(p.cx - guess[0], p.cy - guess[1]);
  if (!(std::abs(p.a) * 2 >= options.min_contrast && sin_between > 0.26 && p.s < radius &&
        shift <= options.max_shift_share * radius))
    return std::nullopt;
  return Vec2{p.cx, p.cy};
}

}  // namespace arpipe::calib
