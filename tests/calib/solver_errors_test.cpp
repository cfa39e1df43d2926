// Bad calibration input gets advice, not a crash: too few views, boards that all face the camera,
// unknown lens models, views that do not match the board or the image size.
#include <gtest/gtest.h>

#include "calib/calibration_solver.h"
#include "tests/calib/solver_test_support.h"

namespace arpipe::calib {
namespace {

using test::kHeight;
using test::kWidth;

template <typename Error, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return {};
  }
  ADD_FAILURE() << "no exception";
  return {};
}

TEST(SolverErrors, ThreeViewsAreTooFew) {
  const auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 3, 0.1, 31);
  const std::string what = message_of<CalibrationError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, SolveOptions{}); });
  EXPECT_NE(what.find("at least 4 views"), std::string::npos) << what;
  EXPECT_NE(what.find("got 3 usable of 3"), std::string::npos) << what;
  EXPECT_NE(what.find("tilted"), std::string::npos) << what;
}

TEST(SolverErrors, ViewsWithTooFewPointsDoNotCount) {
  auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 6, 0.1, 32);
  for (size_t v = 0; v < 2; ++v)
    for (size_t i = 3; i < data.views[v].weights.size(); ++i) data.views[v].weights[i] = 0;  // 3 points left
  for (size_t i = 13; i < data.views[2].weights.size(); ++i) data.views[2].weights[i] = 0;  // one row: a line
  const std::string what = message_of<CalibrationError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, SolveOptions{}); });
  EXPECT_NE(what.find("got 3 usable of 6"), std::string::npos) << what;
  EXPECT_NE(what.find("view002.png"), std::string::npos) << what;
  EXPECT_NE(what.find("view000.png"), std::string::npos) << what;  // named among those with too few points
}

TEST(SolverErrors, AllViewsFrontoParallel) {
  test::ViewSpread facing;
  facing.min_tilt_deg = 0;
  facing.max_tilt_deg = 4;
  const auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 12, 0.1, 33, facing);
  ASSERT_EQ(data.views.size(), 12u);
  const std::string what = message_of<CalibrationError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, SolveOptions{}); });
  EXPECT_NE(what.find("tilt the board 30-45 degrees"), std::string::npos) << what;
}

// One view tilted enough is not refused (the check is "every view nearly face-on").
TEST(SolverErrors, OneTiltedViewIsEnoughToTry) {
  test::ViewSpread facing;
  facing.min_tilt_deg = 0;
  facing.max_tilt_deg = 4;
  auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 8, 0.1, 34, facing);
  const auto tilted = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 2, 0.1, 35);
  data.views.insert(data.views.end(), tilted.views.begin(), tilted.views.end());
  EXPECT_NO_THROW(solve_calibration(data.board, data.views, kWidth, kHeight, SolveOptions{}));
}

TEST(SolverErrors, UnknownLensModel) {
  const auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 6, 0.1, 36);
  SolveOptions options;
  options.lensmodel = "LENSMODEL_FISHEYE9";
  const std::string what = message_of<CameraModelError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, options); });
  EXPECT_NE(what.find("LENSMODEL_FISHEYE9"), std::string::npos) << what;
  // A model mrcal knows but this solver does not calibrate (CAHVORE has no gradients).
  options.lensmodel = "LENSMODEL_CAHVORE_linearity=0.00";
  const std::string cahvore = message_of<CameraModelError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, options); });
  EXPECT_NE(cahvore.find("cannot be calibrated"), std::string::npos) << cahvore;
  options.lensmodel = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=16";  // malformed configuration
  EXPECT_THROW(solve_calibration(data.board, data.views, kWidth, kHeight, options), CameraModelError);
}

TEST(SolverErrors, BoardThatDoesNotMatchTheViews) {
  const auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 6, 0.1, 37);
  CalibrationBoard other = data.board;
  other.rows = 10;
  const std::string what = message_of<CalibrationError>(
      [&] { solve_calibration(other, data.views, kWidth, kHeight, SolveOptions{}); });
  EXPECT_NE(what.find("view000.png"), std::string::npos) << what;
  EXPECT_NE(what.find("does not match"), std::string::npos) << what;
}

TEST(SolverErrors, MixedImageSizes) {
  auto data = test::make_views(test::opencv8_truth(), test::chessboard_9x13(), 6, 0.1, 38);
  data.views[4].width = 320;
  data.views[4].height = 240;
  const std::string what = message_of<CalibrationError>(
      [&] { solve_calibration(data.board, data.views, kWidth, kHeight, SolveOptions{}); });
  EXPECT_NE(what.find("view004.png: image is 320x240"), std::string::npos) << what;
}

}  // namespace
}  // namespace arpipe::calib
