// mrcal's corners cache as written for our views: the layout mrcal.compute_chessboard_corners reads.
#include <gtest/gtest.h>

#include <sstream>

#include "calib/corners_vnl.h"

namespace arpipe::calib {
namespace {

CalibrationBoard board_2x3() {
  CalibrationBoard board;
  board.name = "tiny";
  board.rows = 2;
  board.cols = 3;
  board.spacing_m = 0.01;
  return board;
}

TEST(CornersVnl, RowsInPoolOrderWithWeightsAndMissingPoints) {
  BoardObservation view;
  view.image = "/data/cal 01.png";  // whitespace: mrcal splits rows on it
  view.pixels = {{10, 20}, {11.25, 20}, {12, 20}, {10, 21}, {NAN, NAN}, {-0.5, 21}};
  view.weights = {1, 0.5, -1, 1, 0, 1};
  const std::string text = corners_vnl({view}, board_2x3());
  const std::string expected =
      "# filename x y weight\n"
      "/data/cal_01.png 10 20 1\n"
      "/data/cal_01.png 11.25 20 0.5\n"
      "/data/cal_01.png - - -\n"   // an outlier (weight < 0)
      "/data/cal_01.png 10 21 1\n"
      "/data/cal_01.png - - -\n"   // not seen
      "/data/cal_01.png - - -\n";  // off the image: mrcal drops negative coordinates
  EXPECT_EQ(text, expected);
}

TEST(CornersVnl, GivenNamesAndFullPrecision) {
  BoardObservation view;
  view.image = "recording frame 3";
  view.pixels.assign(6, Vec2{1.0 / 3.0, 2.0 / 3.0});
  view.weights.assign(6, 1.0);
  const std::string text = corners_vnl({view}, board_2x3(), {"frame003.png"});
  std::istringstream lines(text);
  std::string line;
  std::getline(lines, line);
  std::getline(lines, line);
  std::istringstream fields(line);
  std::string name;
  double x = 0, y = 0;
  fields >> name >> x >> y;
  EXPECT_EQ(name, "frame003.png");
  EXPECT_EQ(x, 1.0 / 3.0);  // %.17g round-trips doubles exactly
  EXPECT_EQ(y, 2.0 / 3.0);
}

TEST(CornersVnl, RefusesAViewThatDoesNotMatchTheBoard) {
  BoardObservation view;
  view.image = "a.png";
  view.pixels.assign(5, Vec2{1, 1});
  view.weights.assign(5, 1.0);
  EXPECT_THROW(corners_vnl({view}, board_2x3()), std::invalid_argument);
  EXPECT_THROW(corners_vnl({view, view}, board_2x3(), {"one.png"}), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe::calib
