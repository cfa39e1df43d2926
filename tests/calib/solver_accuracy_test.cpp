// The calibration solve against analytic ground truth: synthetic views of a 9 x 13 board through a
// known lens (tests/calib/solver_test_support.h), for every supported lens model.
#include <gtest/gtest.h>

#include <cmath>

#include "calib/calibration_solver.h"
#include "calib/projection_uncertainty.h"
#include "tests/calib/solver_test_support.h"

namespace arpipe::calib {
namespace {

using test::kHeight;
using test::kWidth;

SolveOptions options_for(const std::string& lensmodel) {
  SolveOptions options;
  options.lensmodel = lensmodel;
  return options;
}

// The pixel grid the projection checks walk: every 40 px, the image's last row and column included.
std::vector<Vec2> check_grid() {
  std::vector<Vec2> grid;
  for (double y : test::pixel_grid(kHeight, 40))
    for (double x : test::pixel_grid(kWidth, 40)) grid.push_back({x, y});
  return grid;
}

// The solve is unbiased and its uncertainty is honest: at every grid pixel, a world point fixed to
// the boards (at infinity: the projection the uncertainty is defined for) lands within 3 predicted
// worst-direction standard deviations of where the true camera sees it, plus 0.02 px for mrcal's
// regularisation bias (0.01 px measured on noise-free views). 3 sigma: a 2-D Gaussian error passes
// its worst-direction 3 sigma with probability <= e^-4.5 ~ 1 %, and the grid's errors are tied
// together by a dozen lens parameters; over 8 seeds the largest ratio measured was 2.3.
void expect_within_uncertainty(const test::SyntheticViews& data, const CameraModel& truth,
                               const CalibrationResult& result, double sigma_px) {
  const std::vector<Vec2> grid = check_grid();
  const auto predicted = projection_uncertainty(result, grid, 0.0, sigma_px);
  ASSERT_EQ(predicted.size(), grid.size());
  double worst_ratio = 0;
  for (size_t i = 0; i < grid.size(); ++i) {
    const Vec2 q = test::fixed_point_projection(truth, data.T_cam_board, result.model, result.T_cam_board, grid[i], 0);
    const double error = std::hypot(q[0] - grid[i][0], q[1] - grid[i][1]);
    const double allowed = 3 * predicted[i].worst_direction_stdev_px + 0.02;
    EXPECT_LT(error, allowed) << "at (" << grid[i][0] << ", " << grid[i][1] << ")";
    worst_ratio = std::max(worst_ratio, error / predicted[i].worst_direction_stdev_px);
  }
  ::testing::Test::RecordProperty("worst_error_over_predicted_stdev", std::to_string(worst_ratio));
}

// The core bounds: fx, fy within 0.5 %, cx, cy within 1 px. At 0.1 px noise on 30 views the
// measured errors are ~0.05 % and ~0.3 px.
void expect_core_near(const CameraModel& solved, const CameraModel& truth) {
  EXPECT_NEAR(solved.fx() / truth.fx(), 1.0, 0.005);
  EXPECT_NEAR(solved.fy() / truth.fy(), 1.0, 0.005);
  EXPECT_NEAR(solved.cx(), truth.cx(), 1.0);
  EXPECT_NEAR(solved.cy(), truth.cy(), 1.0);
}

TEST(SolverAccuracy, Opencv8RecoversTheWideLens) {
  const CameraModel truth = test::opencv8_truth();
  constexpr double kSigma = 0.1;
  const auto data = test::make_views(truth, test::chessboard_9x13(), 30, kSigma, 1);
  ASSERT_EQ(data.views.size(), 30u);
  const CalibrationResult result = solve_calibration(data.board, data.views, kWidth, kHeight, options_for("LENSMODEL_OPENCV8"));
  EXPECT_EQ(result.model.lensmodel(), "LENSMODEL_OPENCV8");
  expect_core_near(result.model, truth);
  // Gaussian noise of sigma per coordinate leaves a per-coordinate RMS of sigma * sqrt(1 - states /
  // measurements) (~0.986 sigma here), and sqrt(2) times that per point; 10 % covers the sampling.
  EXPECT_NEAR(result.rms_per_coordinate_px, kSigma, 0.1 * kSigma);
  EXPECT_NEAR(result.rms_per_point_px, kSigma * std::sqrt(2.0), 0.1 * kSigma * std::sqrt(2.0));
  // Gaussian noise of 0.1 px has no 4-5 sigma outliers to speak of (~0.4 expected among 5850 coordinates).
  EXPECT_LE(result.outlier_count, 2);
  EXPECT_EQ(result.inlier_count + result.outlier_count, 30 * 9 * 13);
  // The board is flat: the warp stays at the noise level (mm-scale warps are what real boards show).
  EXPECT_LT(std::abs(result.board_warp_x_m), 1e-4);
  EXPECT_LT(std::abs(result.board_warp_y_m), 1e-4);
  // Board poses: within 1 mm and 0.1 degree of the truth (the boards are ~0.3-0.55 m away).
  ASSERT_EQ(result.T_cam_board.size(), data.T_cam_board.size());
  for (size_t v = 0; v < data.T_cam_board.size(); ++v) {
    const Vec3 d = result.T_cam_board[v].translation() - data.T_cam_board[v].translation();
    EXPECT_LT(norm(d), 1e-3) << "view " << v;
    EXPECT_LT(rotation_angle_between(result.T_cam_board[v], data.T_cam_board[v]) * 180 / test::kPi, 0.1);
  }
  expect_within_uncertainty(data, truth, result, kSigma);

  // What the result carries: stages in order, and residuals = projected - observed. The solved
  // projection of each corner sits within the fit's error of the noise-free pixel, so a residual is
  // (exact - observed) to within ~sigma * sqrt(states / measurements) ~ 0.02 px RMS; 0.04 px allows
  // for the image's edges, where the fit is least sure.
  ASSERT_EQ(result.residuals_px.size(), 30u);
  ASSERT_EQ(result.stages.size(), 4u);
  EXPECT_EQ(result.stages[0].name, "board poses");
  EXPECT_EQ(result.stages[3].name, "board warp");
  EXPECT_GT(result.seconds, 0);
  double sum = 0, sum_fit = 0;
  int n = 0;
  for (size_t v = 0; v < result.residuals_px.size(); ++v)
    for (size_t i = 0; i < result.residuals_px[v].size(); ++i)
      if (result.observations[v].weights[i] > 0) {
        const Vec2& e = result.residuals_px[v][i];
        const Vec2& observed = data.views[v].pixels[i];
        const Vec2& exact = data.exact_px[v][i];
        sum += e[0] * e[0] + e[1] * e[1];
        sum_fit += std::pow(e[0] - (exact[0] - observed[0]), 2) + std::pow(e[1] - (exact[1] - observed[1]), 2);
        ++n;
      }
  EXPECT_NEAR(std::sqrt(sum / n), result.rms_per_point_px, 1e-12);
  EXPECT_LT(std::sqrt(sum_fit / n), 0.04);
  RecordProperty("fit_rms_px", std::to_string(std::sqrt(sum_fit / n)));
}

// The projection bound, 0.1 px over the whole image. It needs the corners' uncertainty
// well under 0.1/3 px: with 30 views that are at 1.0-1.5 sigma (see the test above), so 0.02 px of
// corner noise. The solved and the true lens are compared as mrcal's projection_diff does, after the
// implied rotation (at infinity): uncompensated, a rotation of the camera that the solve trades
// against cx, cy (worth 0.1-0.6 px here at 0.1 px noise, degrees for the splined model) would be
// counted, though a pose solved through the same lens takes it back.
TEST(SolverAccuracy, Opencv8WithinATenthOfAPixelOverTheWholeImage) {
  const CameraModel truth = test::opencv8_truth();
  const auto data = test::make_views(truth, test::chessboard_9x13(), 30, 0.02, 2);
  const CalibrationResult result = solve_calibration(data.board, data.views, kWidth, kHeight, options_for("LENSMODEL_OPENCV8"));
  expect_core_near(result.model, truth);
  const auto everywhere = [](const Vec2&) { return true; };
  const Mat3 R = test::implied_rotation(truth, result.model, 10, everywhere);
  Vec2 worst{};
  const double difference = test::max_projection_difference_rotated(truth, result.model, R, 5, everywhere, &worst);
  EXPECT_LT(difference, 0.1) << "worst at (" << worst[0] << ", " << worst[1] << ")";
  // The implied rotation is the size of a cx, cy error: hundredths of a degree.
  EXPECT_LT(norm(vector_from_rotation(R)) * 180 / test::kPi, 0.05);
  RecordProperty("max_projection_difference_px", std::to_string(difference));
}

// The splined model where the observations cover the image (inside the board's outline in at least
// one view): it is only known there. Same noise and comparison as above; the fit of the implied
// rotation uses the covered pixels only. Measured over 10 seeds: 0.034-0.086 px, of which ~0.03 px
// is the bias of mrcal's regularisation (noise-free views) and 0.003 px the spline's approximation
// of the OPENCV8 lens.
TEST(SolverAccuracy, SplinedWithinATenthOfAPixelWhereObserved) {
  const CameraModel truth = test::opencv8_truth();
  const auto data = test::make_views(truth, test::chessboard_9x13(), 30, 0.02, 2);
  const CalibrationResult result =
      solve_calibration(data.board, data.views, kWidth, kHeight, options_for("LENSMODEL_SPLINED_STEREOGRAPHIC"));
  // Auto configuration: cubic, 16 x 12 knots for 4:3, the field of view from the presolve plus margin
  // (the lens sees ~70 degrees across).
  EXPECT_EQ(result.model.lensmodel().rfind("LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16_Ny=12_fov_x_deg=", 0), 0u)
      << result.model.lensmodel();
  const auto observed = [&](const Vec2& q) { return test::covered(data, q); };
  const Mat3 R = test::implied_rotation(truth, result.model, 10, observed);
  Vec2 worst{};
  const double difference = test::max_projection_difference_rotated(truth, result.model, R, 5, observed, &worst);
  EXPECT_LT(difference, 0.1) << "worst at (" << worst[0] << ", " << worst[1] << ")";
  RecordProperty("max_projection_difference_px", std::to_string(difference));
}

TEST(SolverAccuracy, SplinedWithAGivenConfiguration) {
  const CameraModel truth = test::opencv8_truth();
  const auto data = test::make_views(truth, test::chessboard_9x13(), 25, 0.1, 3);
  const std::string name = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=12_Ny=9_fov_x_deg=90";
  const CalibrationResult result = solve_calibration(data.board, data.views, kWidth, kHeight, options_for(name));
  EXPECT_EQ(result.model.lensmodel(), name);
  EXPECT_EQ(result.model.intrinsics().size(), 4u + 2 * 12 * 9);
  EXPECT_NEAR(result.rms_per_coordinate_px, 0.1, 0.01);
}

TEST(SolverAccuracy, PinholeOnAPinholeLens) {
  const CameraModel truth = test::pinhole_truth();
  constexpr double kSigma = 0.1;
  const auto data = test::make_views(truth, test::chessboard_9x13(), 25, kSigma, 4);
  const CalibrationResult result = solve_calibration(data.board, data.views, kWidth, kHeight, options_for("LENSMODEL_PINHOLE"));
  EXPECT_EQ(result.model.lensmodel(), "LENSMODEL_PINHOLE");
  expect_core_near(result.model, truth);
  EXPECT_NEAR(result.rms_per_coordinate_px, kSigma, 0.1 * kSigma);
  expect_within_uncertainty(data, truth, result, kSigma);
}

TEST(SolverAccuracy, Opencv4AndOpencv5OnTheirOwnLenses) {
  constexpr double kSigma = 0.1;
  for (const auto& [name, truth] : {std::pair{std::string("LENSMODEL_OPENCV4"), test::opencv4_truth()},
                                    std::pair{std::string("LENSMODEL_OPENCV5"), test::opencv5_truth()}}) {
    SCOPED_TRACE(name);
    const auto data = test::make_views(truth, test::chessboard_9x13(), 25, kSigma, 5);
    const CalibrationResult result = solve_calibration(data.board, data.views, kWidth, kHeight, options_for(name));
    EXPECT_EQ(result.model.lensmodel(), name);
    expect_core_near(result.model, truth);
    // The distortion itself: k1 within 2 % (measured ~0.5 %).
    EXPECT_NEAR(result.model.intrinsics()[4] / truth.intrinsics()[4], 1.0, 0.02);
    EXPECT_NEAR(result.rms_per_coordinate_px, kSigma, 0.1 * kSigma);
    expect_within_uncertainty(data, truth, result, kSigma);
  }
}

// A focal-length guess skips the search and gives the same solve.
TEST(SolverAccuracy, GivenFocalGuess) {
  const CameraModel truth = test::opencv8_truth();
  const auto data = test::make_views(truth, test::chessboard_9x13(), 20, 0.1, 6);
  SolveOptions options = options_for("LENSMODEL_OPENCV8");
  const CalibrationResult guessed = solve_calibration(data.board, data.views, kWidth, kHeight, options);
  options.focal_guess_px = 450;
  const CalibrationResult given = solve_calibration(data.board, data.views, kWidth, kHeight, options);
  // Same data, same optimum: the intrinsics agree far below their uncertainty (~0.3 px for cx).
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(given.model.intrinsics()[i], guessed.model.intrinsics()[i], 1e-3);
}

// Progress reports every stage before it runs; no warp stage when the warp is not wanted.
TEST(SolverAccuracy, ProgressAndStagesWithoutWarp) {
  const auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 12, 0.1, 7);
  SolveOptions options = options_for("LENSMODEL_OPENCV8");
  options.optimize_board_warp = false;
  std::vector<std::string> names;
  const CalibrationResult result =
      solve_calibration(data.board, data.views, kWidth, kHeight, options, [&](int index, int count, const std::string& n) {
        EXPECT_EQ(index, int(names.size()));
        EXPECT_EQ(count, 3);
        names.push_back(n);
      });
  EXPECT_EQ(names, (std::vector<std::string>{"board poses", "core intrinsics", "full model"}));
  ASSERT_EQ(result.stages.size(), 3u);
  EXPECT_EQ(result.board_warp_x_m, 0.0);
  // Each stage fits at least as well as the one before.
  for (size_t i = 1; i < result.stages.size(); ++i)
    EXPECT_LE(result.stages[i].rms_per_coordinate_px, result.stages[i - 1].rms_per_coordinate_px * 1.0001);
}

}  // namespace
}  // namespace arpipe::calib
