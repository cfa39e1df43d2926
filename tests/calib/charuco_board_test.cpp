// ChArUco board files (configs/boards/charuco-*.toml): the shipped one loads as its comment says,
// its points are OpenCV's ChArUco corners in mrcal's layout, every mistake is named with the file,
// the place and the key; and part of the printed board is a view with its corners named.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "calib/board_detector.h"
#include "calib/board_printout.h"
#include "calib/calibration_board.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

const std::string kCharuco = "kind = \"charuco\"\n";

TEST(CharucoBoardFile, ShippedBoard) {
  const CalibrationBoard board = load_board(fs::path(ARPIPE_SOURCE_DIR) / "configs/boards/charuco-10x14-20mm.toml");
  EXPECT_EQ(board.kind, BoardKind::charuco);
  EXPECT_EQ(board.rows, 9);
  EXPECT_EQ(board.cols, 13);
  EXPECT_DOUBLE_EQ(board.spacing_m, 0.02);
  EXPECT_DOUBLE_EQ(board.marker_m, 0.015);
  EXPECT_EQ(board.dictionary, "DICT_5X5_100");
  EXPECT_EQ(board.dictionary_id, cv::aruco::DICT_5X5_100);
}

// OpenCV's ChArUco corner with id k lies at ((k % cols + 1) s, (k / cols + 1) s) from the board's
// outer corner: the board file's point k, shifted by one square.
TEST(CharucoBoardFile, PointsAreOpenCVsCornersInMrcalsLayout) {
  const CalibrationBoard board = load_board(fs::path(ARPIPE_SOURCE_DIR) / "configs/boards/charuco-10x14-20mm.toml");
  const auto charuco = cv::aruco::CharucoBoard::create(board.cols + 1, board.rows + 1, float(board.spacing_m),
                                                       float(board.marker_m),
                                                       cv::aruco::getPredefinedDictionary(board.dictionary_id));
  const std::vector<Vec3> points = board.points();
  ASSERT_EQ(charuco->chessboardCorners.size(), points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    EXPECT_NEAR(charuco->chessboardCorners[k].x - board.spacing_m, points[k][0], 1e-7) << k;
    EXPECT_NEAR(charuco->chessboardCorners[k].y - board.spacing_m, points[k][1], 1e-7) << k;
  }
}

TEST(CharucoBoardFile, MistakesAreNamed) {
  const std::string ok = "squares = [10, 14]\nsquare_m = 0.02\nmarker_m = 0.015\n";
  EXPECT_EQ(board_error_of(kCharuco + ok + "dictionary = \"DICT_5X5_100\"\n"), "");
  EXPECT_EQ(board_error_of(kCharuco + ok + "dictionary = \"DICT_9X9_1\"\n"),
            "b.toml:5:14: dictionary: expected one of DICT_4X4_50, DICT_4X4_100, DICT_4X4_250, DICT_4X4_1000, "
            "DICT_5X5_50, DICT_5X5_100, DICT_5X5_250, DICT_5X5_1000, DICT_6X6_50, DICT_6X6_100, DICT_6X6_250, "
            "DICT_6X6_1000, DICT_7X7_50, DICT_7X7_100, DICT_7X7_250, DICT_7X7_1000, DICT_ARUCO_ORIGINAL, "
            "DICT_APRILTAG_16h5, DICT_APRILTAG_25h9, DICT_APRILTAG_36h10, DICT_APRILTAG_36h11, found \"DICT_9X9_1\"");
  EXPECT_NE(board_error_of(kCharuco + ok).find("b.toml:1:1: dictionary: expected one of DICT_4X4_50"), std::string::npos)
      << board_error_of(kCharuco + ok);
  // 140 squares hold 70 markers: DICT_5X5_50 has 50 codes.
  EXPECT_EQ(board_error_of(kCharuco + ok + "dictionary = \"DICT_5X5_50\"\n"),
            "b.toml:2:11: squares: expected at most 50 markers (DICT_5X5_50 has 50 codes; a board has one per light "
            "square), found 10 x 14 squares, 70 markers");
  EXPECT_EQ(board_error_of(kCharuco + "squares = [10, 14]\nsquare_m = 0.02\nmarker_m = 0.02\ndictionary = \"DICT_5X5_100\"\n"),
            "b.toml:4:12: marker_m: expected less than square_m (0.02 m): the marker sits inside a light square, "
            "found 0.02");
  EXPECT_EQ(board_error_of(kCharuco + "squares = [2, 14]\nsquare_m = 0.02\nmarker_m = 0.015\ndictionary = \"DICT_5X5_100\"\n"),
            "b.toml:2:11: squares: expected at least 3 squares each way (2 x 2 inner corners), found 2 x 14");
  EXPECT_EQ(board_error_of(kCharuco + ok + "dictionary = \"DICT_5X5_100\"\ninner_corners = [9, 13]\n"),
            "b.toml:6:1: inner_corners: unknown key; allowed keys in the top level: kind, description, squares, "
            "square_m, marker_m, dictionary");
  EXPECT_EQ(board_error_of(kCharuco + "squares = [10, 14]\nsquare_m = 0.02\nmarker_m = -1\ndictionary = \"DICT_5X5_100\"\n"),
            "b.toml:4:12: marker_m: expected a number > 0 (m), found -1.0");
}

// Part of the printed board (its top-left corner, cut by the image's edge): the corners seen are
// named by their markers and placed where they are drawn; a part with fewer than 12 corners is no
// view (board_detector.cpp, kMinCharucoCorners). Drawn at 100 dpi, lightly blurred (a camera's
// optics; the blur is symmetric about each corner, so it moves none).
TEST(CharucoBoardDetection, PartOfTheBoardIsFoundWithItsCornersNamed) {
  const CalibrationBoard board = load_board(fs::path(ARPIPE_SOURCE_DIR) / "configs/boards/charuco-10x14-20mm.toml");
  const fs::path dir = scratch_dir("charuco-part");
  constexpr double kPxPerM = 100 / 0.0254;
  write_board_png(board, dir / "board.png", 100);
  cv::Mat image = cv::imread((dir / "board.png").string(), cv::IMREAD_GRAYSCALE);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  const auto rounded = [&](double metres) { return double(std::lround(metres * kPxPerM)); };
  const BoardDetector detector(board);
  // The margin and 6 x 5 squares: inner corners of rows 0-3, columns 0-4 (20), the outer ones
  // with a marker cut in half.
  for (const auto& [squares_x, squares_y, expect_view] : {std::tuple{6.5, 5.5, true}, std::tuple{3.5, 3.5, false}}) {
    const cv::Mat part = image(cv::Rect(0, 0, int(rounded((1 + squares_x) * board.spacing_m)),
                                        int(rounded((1 + squares_y) * board.spacing_m))))
                             .clone();
    const auto view = detector.detect(part.data, part.cols, part.rows, part.step, "part");
    ASSERT_EQ(view.has_value(), expect_view) << squares_x << " x " << squares_y << " squares";
    if (!view) continue;
    EXPECT_GE(view->seen_count(), 12);
    EXPECT_LT(view->seen_count(), board.point_count());
    for (int r = 0; r < board.rows; ++r)
      for (int c = 0; c < board.cols; ++c) {
        const size_t i = size_t(r * board.cols + c);
        if (view->weights[i] <= 0) continue;
        EXPECT_LT(c, int(squares_x)) << "corner " << i << " is outside the part";
        EXPECT_LT(r, int(squares_y)) << "corner " << i << " is outside the part";
        EXPECT_NEAR(view->pixels[i][0], rounded((c + 2) * board.spacing_m) - 0.5, 0.1) << "corner " << i;
        EXPECT_NEAR(view->pixels[i][1], rounded((r + 2) * board.spacing_m) - 0.5, 0.1) << "corner " << i;
      }
  }
  remove_scratch(dir);
}

}  // namespace
}  // namespace arpipe::calib
