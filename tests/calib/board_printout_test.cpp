// The printable board: drawn at a known resolution, every board file's picture is found by its own
// detector with the points exactly where the geometry puts them, so what the user prints is what
// the board file describes.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "calib/board_detector.h"
#include "calib/board_printout.h"
#include "calib/calibration_board.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

constexpr double kDpi = 100;
constexpr double kPxPerM = kDpi / 0.0254;

double rounded(double metres) { return double(std::lround(metres * kPxPerM)); }

// Where point (row, col) lies in the picture, from the edges as drawn (board_printout rounds each
// edge to whole pixels): a chessboard corner sits on the pixel boundary between squares, a tag
// centre halfway between its black square's edges. mrcal's convention puts pixel centres at
// integers, so a boundary drawn at x px lies at x - 0.5.
Vec2 expected_pixel(const CalibrationBoard& board, int row, int col) {
  if (board.kind == BoardKind::chessboard || board.kind == BoardKind::charuco)
    return {rounded((col + 2) * board.spacing_m) - 0.5, rounded((row + 2) * board.spacing_m) - 0.5};
  const double margin = (board.spacing_m - board.tag_size_m) + board.tag_size_m / 8;  // gap + one white cell
  const auto centre = [&](int i) {
    const double near = margin + i * board.spacing_m;
    return (rounded(near) + rounded(near + board.tag_size_m)) / 2 - 0.5;
  };
  return {centre(col), centre(row)};
}

class BoardPrintout : public ::testing::TestWithParam<const char*> {};

TEST_P(BoardPrintout, IsFoundWithEveryPointWhereTheBoardFileSays) {
  const CalibrationBoard board = load_board(std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs/boards" / GetParam());
  const auto png = test::scratch_dir(std::string("printout-") + GetParam()) / "board.png";
  const PrintedBoard printed = write_board_png(board, png, kDpi);
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(image.cols, printed.width_px);
  EXPECT_NEAR(printed.width_m, image.cols / kPxPerM, 1e-12);
  const auto view = BoardDetector(board).detect(image.data, image.cols, image.rows, image.step, png.string());
  ASSERT_TRUE(view) << "the printed board is not found by its own detector";
  ASSERT_EQ(view->seen_count(), board.point_count());
  // On an ideal picture the detectors' sub-pixel fits land within a tenth of a pixel of the drawn
  // corners; a 180-degree turn of the point order is the same board (the detector may report either).
  double straight = 0, turned = 0;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c) {
      const Vec2& q = view->pixels[size_t(r * board.cols + c)];
      const Vec2 a = expected_pixel(board, r, c);
      const Vec2 b = expected_pixel(board, board.rows - 1 - r, board.cols - 1 - c);
      straight = std::max(straight, std::hypot(q[0] - a[0], q[1] - a[1]));
      turned = std::max(turned, std::hypot(q[0] - b[0], q[1] - b[1]));
    }
  EXPECT_LT(std::min(straight, turned), 0.1);
}

INSTANTIATE_TEST_SUITE_P(EveryBoardFile, BoardPrintout,
                         ::testing::Values("chessboard-10x14-20mm.toml", "chessboard-10x10-mrgingham.toml",
                                           "aprilgrid-6x8-tag36h11.toml", "charuco-10x14-20mm.toml"));

TEST(BoardPrintoutErrors, AnImpossibleResolutionOrPathIsNamed) {
  const CalibrationBoard board =
      load_board(std::filesystem::path(ARPIPE_SOURCE_DIR) / "configs/boards/chessboard-10x14-20mm.toml");
  try {
    write_board_png(board, "/tmp/never.png", 5);
    FAIL() << "5 dpi accepted";
  } catch (const BoardError& e) {
    EXPECT_NE(std::string(e.what()).find("dots per inch"), std::string::npos) << e.what();
  }
  try {
    write_board_png(board, "/nonexistent-dir/board.png", 300);
    FAIL() << "unwritable path accepted";
  } catch (const BoardError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/board.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe::calib
