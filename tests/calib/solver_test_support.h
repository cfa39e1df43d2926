// Synthetic board views with analytic ground truth for the calibration-solver tests: a known lens, a
// 9 x 13-corner board, poses spread over the image and tilted, Gaussian corner noise.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"

namespace arpipe::calib::test {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kPi = 3.14159265358979323846;

// The lens of configs/sim/calib-board.toml: a wide webcam's barrel distortion (OPENCV8).
inline CameraModel opencv8_truth() {
  return CameraModel("LENSMODEL_OPENCV8",
                     {520.0, 521.5, 323.0, 237.0, -0.28, 0.11, 0.0005, -0.0004, -0.02, 0.04, 0.01, 0.0}, kWidth,
                     kHeight);
}
inline CameraModel pinhole_truth() { return CameraModel::pinhole(520.0, 521.5, 323.0, 237.0, kWidth, kHeight); }
// A milder lens that OPENCV4 (k1, k2, p1, p2) and OPENCV5 (+k3) describe exactly.
inline CameraModel opencv5_truth() {
  return CameraModel("LENSMODEL_OPENCV5", {520.0, 521.5, 323.0, 237.0, -0.21, 0.06, 0.0005, -0.0004, -0.01}, kWidth,
                     kHeight);
}
inline CameraModel opencv4_truth() {
  return CameraModel("LENSMODEL_OPENCV4", {520.0, 521.5, 323.0, 237.0, -0.21, 0.06, 0.0005, -0.0004}, kWidth, kHeight);
}

// The calib-board scene's board: 10 x 14 squares of 20 mm, so 9 x 13 inner corners.
inline CalibrationBoard chessboard_9x13() {
  CalibrationBoard board;
  board.name = "synthetic-9x13";
  board.kind = BoardKind::chessboard;
  board.rows = 9;
  board.cols = 13;
  board.spacing_m = 0.02;
  return board;
}

struct ViewSpread {
  double min_tilt_deg = 15;   // board normal against the line of sight
  double max_tilt_deg = 45;
  double min_distance_m = 0.28;
  double max_distance_m = 0.55;
  double max_roll_deg = 25;
  double margin_px = 3;       // every corner this far inside the image
};

struct SyntheticViews {
  CalibrationBoard board;
  std::vector<BoardObservation> views;
  std::vector<SE3> T_cam_board;            // truth
  std::vector<std::vector<Vec2>> exact_px;  // noise-free pixels
};

inline Mat3 axis_angle(const Vec3& axis, double angle) { return rotation_from_vector(angle * normalized(axis)); }

// `count` views whose board centres sweep the image on a grid (so the corners and edges of the image
// are covered), each tilted by a random angle about a random in-plane axis, at a random distance.
// Noise: independent Gaussian of `sigma_px` on x and y of every corner. Deterministic for a seed.
inline SyntheticViews make_views(const CameraModel& truth, const CalibrationBoard& board, int count, double sigma_px,
                                 unsigned seed, const ViewSpread& spread = {}) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_px > 0 ? sigma_px : 1.0);  // stddev must be > 0
  SyntheticViews out;
  out.board = board;
  const double board_w = (board.cols - 1) * board.spacing_m, board_h = (board.rows - 1) * board.spacing_m;
  // Aim points: a 5 x 4 grid over the image, visited in a scrambled but fixed order.
  const int gx = 5, gy = 4;
  for (int k = 0, attempt = 0; k < count && attempt < 100000; ++attempt) {
    const int cell = (k * 7) % (gx * gy);
    const double u = ((cell % gx) + unit(random)) / gx, w = ((cell / gx) + unit(random)) / gy;
    const Vec2 aim{u * truth.width(), w * truth.height()};
    const auto ray = truth.unproject(aim);
    if (!ray) continue;
    const double distance = spread.min_distance_m + unit(random) * (spread.max_distance_m - spread.min_distance_m);
    const Vec3 centre = (distance / norm(*ray)) * *ray;
    // Start facing the camera along the ray, then tilt and roll.
    const Vec3 z_axis = normalized(*ray);  // board normal points away from the camera (board z into it)
    const Vec3 x0 = normalized(cross(Vec3{0, 1, 0}, z_axis));
    const Vec3 y0 = cross(z_axis, x0);
    Mat3 R_face{};
    for (int i = 0; i < 3; ++i) R_face[i] = {x0[i], y0[i], z_axis[i]};
    const double tilt =
        (spread.min_tilt_deg + unit(random) * (spread.max_tilt_deg - spread.min_tilt_deg)) * kPi / 180;
    const double axis_angle_rad = unit(random) * 2 * kPi;
    const double roll = (2 * unit(random) - 1) * spread.max_roll_deg * kPi / 180;
    const Mat3 R = mat_mul(mat_mul(R_face, axis_angle({std::cos(axis_angle_rad), std::sin(axis_angle_rad), 0}, tilt)),
                           axis_angle({0, 0, 1}, roll));
    const Vec3 t = centre - mat_mul(R, Vec3{board_w / 2, board_h / 2, 0});
    const SE3 T(R, t);
    std::vector<Vec3> p(size_t(board.point_count()));
    for (int r = 0; r < board.rows; ++r)
      for (int c = 0; c < board.cols; ++c) p[size_t(r * board.cols + c)] = T * board.point(r, c);
    std::vector<Vec2> q;
    truth.project(p, q);
    const bool inside = std::all_of(q.begin(), q.end(), [&](const Vec2& px) {
      return std::isfinite(px[0]) && px[0] >= spread.margin_px && px[0] <= truth.width() - 1 - spread.margin_px &&
             px[1] >= spread.margin_px && px[1] <= truth.height() - 1 - spread.margin_px;
    });
    if (!inside) continue;
    BoardObservation obs;
    obs.image = "view" + std::to_string(1000 + k).substr(1) + ".png";
    obs.width = truth.width();
    obs.height = truth.height();
    obs.detector = "synthetic";
    obs.pixels = q;
    if (sigma_px > 0)
      for (Vec2& px : obs.pixels) px = {px[0] + noise(random), px[1] + noise(random)};
    obs.weights.assign(q.size(), 1.0);
    out.views.push_back(std::move(obs));
    out.T_cam_board.push_back(T);
    out.exact_px.push_back(std::move(q));
    ++k;
  }
  return out;
}

// Where the observations cover the image: inside the outline of the board in at least one view.
inline bool covered(const SyntheticViews& data, const Vec2& pixel) {
  const int rows = data.board.rows, cols = data.board.cols;
  for (const auto& q : data.exact_px) {
    std::vector<cv::Point2f> outline;
    for (int c = 0; c < cols; ++c) outline.emplace_back(float(q[size_t(c)][0]), float(q[size_t(c)][1]));
    for (int r = 1; r < rows; ++r)
      outline.emplace_back(float(q[size_t(r * cols + cols - 1)][0]), float(q[size_t(r * cols + cols - 1)][1]));
    for (int c = cols - 2; c >= 0; --c)
      outline.emplace_back(float(q[size_t((rows - 1) * cols + c)][0]), float(q[size_t((rows - 1) * cols + c)][1]));
    for (int r = rows - 2; r > 0; --r) outline.emplace_back(float(q[size_t(r * cols)][0]), float(q[size_t(r * cols)][1]));
    if (cv::pointPolygonTest(outline, cv::Point2f(float(pixel[0]), float(pixel[1])), false) >= 0) return true;
  }
  return false;
}

// Largest |q_solved - q_true| over a grid of pixels (every `step` px, the image's edges included):
// each pixel's ray under the true lens, projected by the solved lens. No implied transform is fitted
// (mrcal's projection_diff fits one between two independent calibrations): both models describe the
// same camera frame, the one the true lens defines, because the solve estimates the intrinsics
// against board poses that are free, not against a rotated camera; any rotation the solve gets wrong
// shows up as an error in cx, cy, which this test must see.
// 0, step, 2 step, ... and the last pixel, n - 1.
inline std::vector<double> pixel_grid(int n, double step) {
  std::vector<double> v;
  for (double x = 0; x < n - 1; x += step) v.push_back(x);
  v.push_back(n - 1);
  return v;
}

template <typename Mask>
double max_projection_difference(const CameraModel& truth, const CameraModel& solved, double step, Mask in_mask,
                                 Vec2* worst_pixel = nullptr) {
  double worst = 0;
  for (double y : pixel_grid(truth.height(), step))
    for (double x : pixel_grid(truth.width(), step)) {
      const Vec2 q{x, y};
      if (!in_mask(q)) continue;
      const auto ray = truth.unproject(q);
      const auto q2 = ray ? solved.project(*ray) : std::nullopt;
      if (!q2) return INFINITY;
      const double d = std::hypot((*q2)[0] - q[0], (*q2)[1] - q[1]);
      if (d > worst) {
        worst = d;
        if (worst_pixel) *worst_pixel = q;
      }
    }
  return worst;
}
// The rotation R that best maps the true lens's rays onto the solved lens's rays for the same pixels
// (least squares over a pixel grid, Kabsch): the "implied transform" of mrcal's projection_diff for
// points at infinity. A small error in cx, cy and an equally small rotation of the camera explain
// the observations almost equally well, so each solve picks its own mix; a world point seen through
// the solved camera and a pose solved with the same lens lands where R says.
template <typename Mask>
Mat3 implied_rotation(const CameraModel& truth, const CameraModel& solved, double step, Mask in_mask) {
  cv::Matx33d H = cv::Matx33d::zeros();
  for (double y : pixel_grid(truth.height(), step))
    for (double x : pixel_grid(truth.width(), step)) {
      const Vec2 q{x, y};
      if (!in_mask(q)) continue;
      const auto a = truth.unproject(q);
      const auto b = solved.unproject(q);
      if (!a || !b) continue;
      const Vec3 u = normalized(*a), w = normalized(*b);
      H += cv::Matx31d(w[0], w[1], w[2]) * cv::Matx13d(u[0], u[1], u[2]);
    }
  cv::SVD svd(cv::Mat(H), cv::SVD::FULL_UV);
  cv::Mat R = svd.u * svd.vt;
  if (cv::determinant(R) < 0) {
    cv::Mat u = svd.u.clone();
    u.col(2) *= -1;
    R = u * svd.vt;
  }
  Mat3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[size_t(i)][size_t(j)] = R.at<double>(i, j);
  return out;
}

// As max_projection_difference, after mapping the true rays by R (implied_rotation).
template <typename Mask>
double max_projection_difference_rotated(const CameraModel& truth, const CameraModel& solved, const Mat3& R,
                                         double step, Mask in_mask, Vec2* worst_pixel = nullptr) {
  double worst = 0;
  for (double y : pixel_grid(truth.height(), step))
    for (double x : pixel_grid(truth.width(), step)) {
      const Vec2 q{x, y};
      if (!in_mask(q)) continue;
      const auto ray = truth.unproject(q);
      const auto q2 = ray ? solved.project(mat_mul(R, *ray)) : std::nullopt;
      if (!q2) return INFINITY;
      const double d = std::hypot((*q2)[0] - q[0], (*q2)[1] - q[1]);
      if (d > worst) {
        worst = d;
        if (worst_pixel) *worst_pixel = q;
      }
    }
  return worst;
}

// Where the solved calibration puts a world point that the true camera sees at pixel q, at
// `distance_m` (0: at infinity) along its ray: the point is fixed to the boards (its coordinates in
// each true board frame), brought into the solved camera through each solved board pose, averaged
// over the views and projected by the solved lens. This is the quantity whose spread mrcal's
// projection uncertainty predicts (uncertainty.org): the mean over the frames removes the rotation
// that a solve may trade against cx, cy.
inline Vec2 fixed_point_projection(const CameraModel& truth, const std::vector<SE3>& T_true,
                                   const CameraModel& solved, const std::vector<SE3>& T_solved, const Vec2& q,
                                   double distance_m) {
  const Vec3 ray = normalized(*truth.unproject(q));
  Vec3 mean{0, 0, 0};
  const double share = 1.0 / double(T_true.size());
  for (size_t v = 0; v < T_true.size(); ++v) {
    const Vec3 p = distance_m > 0 ? T_solved[v] * (T_true[v].inverse() * (distance_m * ray))
                                  : T_solved[v].rotate(T_true[v].inverse().rotate(ray));
    mean = mean + share * p;
  }
  const auto q2 = solved.project(mean);
  return q2 ? *q2 : Vec2{INFINITY, INFINITY};
}

inline double max_projection_difference(const CameraModel& truth, const CameraModel& solved, double step = 10) {
  return max_projection_difference(truth, solved, step, [](const Vec2&) { return true; });
}

}  // namespace arpipe::calib::test
