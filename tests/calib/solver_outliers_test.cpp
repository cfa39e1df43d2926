// Outlier rejection in the calibration solve: corners a detector put several pixels off are marked
// and do not move the solution.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "calib/calibration_solver.h"
#include "tests/calib/solver_test_support.h"

namespace arpipe::calib {
namespace {

TEST(SolverOutliers, DisplacedCornersAreRejectedAndChangeNothing) {
  const CameraModel truth = test::opencv8_truth();
  constexpr double kSigma = 0.1;
  const auto clean = test::make_views(truth, test::chessboard_9x13(), 25, kSigma, 21);
  ASSERT_EQ(clean.views.size(), 25u);

  // Eight corners in six views pushed 5 to 8 px in assorted directions (50-80 sigma).
  struct Displacement {
    size_t view, point;
    double dx, dy;
  };
  const std::vector<Displacement> displaced = {{0, 0, 5, 0},      {3, 58, 0, -6},   {3, 59, -4, 4},
                                               {7, 116, 6, 3},    {12, 40, -7, -2}, {12, 95, 3, -5},
                                               {18, 13, 0, 8},    {24, 70, -5, -5}};
  auto views = clean.views;
  for (const auto& d : displaced) {
    views[d.view].pixels[d.point][0] += d.dx;
    views[d.view].pixels[d.point][1] += d.dy;
  }
  SolveOptions options;
  options.lensmodel = "LENSMODEL_OPENCV8";
  const CalibrationResult result = solve_calibration(clean.board, views, test::kWidth, test::kHeight, options);
  const CalibrationResult reference = solve_calibration(clean.board, clean.views, test::kWidth, test::kHeight, options);
  // Every displaced corner is marked (weight < 0) and its residual shows the displacement.
  for (const auto& d : displaced) {
    EXPECT_LT(result.observations[d.view].weights[d.point], 0) << "view " << d.view << " point " << d.point;
    const Vec2& e = result.residuals_px[d.view][d.point];
    EXPECT_NEAR(std::hypot(e[0], e[1]), std::hypot(d.dx, d.dy), 0.5) << "view " << d.view << " point " << d.point;
  }
  // mrcal marks what lies beyond 4 sigma once anything lies beyond 5 sigma: with Gaussian noise of
  // 0.1 px, ~0.4 of the 5850 clean coordinates pass 4 sigma, so at most a couple of extra marks.
  EXPECT_GE(result.outlier_count, int(displaced.size()));
  EXPECT_LE(result.outlier_count, int(displaced.size()) + 2);
  EXPECT_EQ(result.stages.back().outliers, result.outlier_count);
  // The input's weights are kept for the inliers.
  std::set<std::pair<size_t, size_t>> moved;
  for (const auto& d : displaced) moved.insert({d.view, d.point});
  for (size_t v = 0; v < views.size(); ++v)
    for (size_t i = 0; i < views[v].weights.size(); ++i)
      if (!moved.count({v, i})) {
        EXPECT_TRUE(result.observations[v].weights[i] == 1.0 || result.observations[v].weights[i] == -1.0);
      }

  // The rest of the data is the clean data less 8 points: a world point fixed to the boards lands
  // where the clean solve puts it to within 0.1 px everywhere (measured 0.034 px: the dropped points
  // include board corners near the image's corners, where the clean solve's own uncertainty is
  // ~0.2 px). Without rejection the same corners move it by 3.3 px (measured).
  const auto moved_by = [&](const CalibrationResult& r) {
    double worst = 0;
    for (double y : test::pixel_grid(test::kHeight, 20))
      for (double x : test::pixel_grid(test::kWidth, 20)) {
        const Vec2 q = test::fixed_point_projection(reference.model, reference.T_cam_board, r.model, r.T_cam_board,
                                                    {x, y}, 0);
        worst = std::max(worst, std::hypot(q[0] - x, q[1] - y));
      }
    return worst;
  };
  EXPECT_LT(moved_by(result), 0.1);
  SolveOptions keep_all = options;
  keep_all.reject_outliers = false;
  EXPECT_GT(moved_by(solve_calibration(clean.board, views, test::kWidth, test::kHeight, keep_all)), 1.0);
  EXPECT_NEAR(result.rms_per_coordinate_px, reference.rms_per_coordinate_px, 0.005);
  EXPECT_NEAR(result.model.fx() / truth.fx(), 1.0, 0.005);
  EXPECT_NEAR(result.model.cx(), truth.cx(), 1.0);
}

// Partial boards (points not seen, weight 0) are neither used nor counted as outliers.
TEST(SolverOutliers, MissingPointsAreNotOutliers) {
  auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 20, 0.1, 22);
  int hidden = 0;
  for (size_t v = 0; v < data.views.size(); v += 2)
    for (int c = 0; c < 13; ++c) {
      data.views[v].weights[size_t(c)] = 0;  // the first row not seen
      data.views[v].pixels[size_t(c)] = {NAN, NAN};
      ++hidden;
    }
  SolveOptions options;
  options.lensmodel = "LENSMODEL_OPENCV8";
  const CalibrationResult result = solve_calibration(data.board, data.views, test::kWidth, test::kHeight, options);
  EXPECT_LE(result.outlier_count, 2);
  EXPECT_EQ(result.inlier_count + result.outlier_count, 20 * 117 - hidden);
  EXPECT_TRUE(std::isnan(result.residuals_px[0][0][0]));
  EXPECT_EQ(result.observations[0].weights[0], 0.0);
}

// Corners far better than any detector's (0.001 px of noise): the residuals are then mrcal's
// regularisation bias, whose weight is fixed for ~1 px of noise (mrcal 2.2, mrcal.c:
// normal_pixel_error = 1.0), not noise. Measured with `arpipe bench calib-solve --sigma 0.001`:
// OPENCV8 residuals 0.0031 px per coordinate with the regularisation, 0.0010 (the noise) without
// it; without the outlier rule's floor (mrcal_problem.cpp, kOutlierSigmaFloorPx) a splined solve
// marked up to 2201 of 11700 corners as outliers, and on these views 179, ending 2.6 px from the
// true lens where the board was seen (measured with the floor set to 0).
TEST(SolverOutliers, RegularisationBiasIsNotTakenForOutliers) {
  const CameraModel truth = test::opencv8_truth();
  const auto data = test::make_views(truth, test::chessboard_9x13(), 30, 0.001, 3030);

  SolveOptions opencv8;
  opencv8.lensmodel = "LENSMODEL_OPENCV8";
  const CalibrationResult regularised = solve_calibration(data.board, data.views, test::kWidth, test::kHeight, opencv8);
  SolveOptions unregularised = opencv8;
  unregularised.regularize = false;
  const CalibrationResult plain = solve_calibration(data.board, data.views, test::kWidth, test::kHeight, unregularised);
  // The RMS per coordinate of 11700 Gaussian draws of sigma 0.001 is within 2 % of it.
  EXPECT_NEAR(plain.rms_per_coordinate_px, 0.001, 0.00002);
  EXPECT_GT(regularised.rms_per_coordinate_px, 2 * 0.001);
  EXPECT_EQ(regularised.outlier_count, 0);

  SolveOptions splined;
  splined.lensmodel = "LENSMODEL_SPLINED_STEREOGRAPHIC";
  const CalibrationResult result = solve_calibration(data.board, data.views, test::kWidth, test::kHeight, splined);
  EXPECT_EQ(result.outlier_count, 0);
  const auto observed = [&](const Vec2& q) { return test::covered(data, q); };
  const Mat3 R = test::implied_rotation(truth, result.model, 10, observed);
  EXPECT_LT(test::max_projection_difference_rotated(truth, result.model, R, 5, observed), 0.1);
}

}  // namespace
}  // namespace arpipe::calib
