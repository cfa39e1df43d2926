// Board files (configs/boards/*.toml): the shipped ones load with the boards their comments
// describe, the point grid is mrcal's layout, and every kind of mistake is named with its place.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "calib/calibration_board.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

const fs::path kBoards = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "boards";

const std::string kChess = "kind = \"chessboard\"\n";
const std::string kGrid = "kind = \"apriltag_grid\"\n";

TEST(BoardFile, ShippedChessboardOfTheCalibScene) {
  const CalibrationBoard board = load_board(kBoards / "chessboard-10x14-20mm.toml");
  EXPECT_EQ(board.name, "chessboard-10x14-20mm");
  EXPECT_EQ(board.kind, BoardKind::chessboard);
  // configs/sim/calib-board.toml: 10 x 14 squares of 20 mm.
  EXPECT_EQ(board.rows, 9);
  EXPECT_EQ(board.cols, 13);
  EXPECT_DOUBLE_EQ(board.spacing_m, 0.020);
  EXPECT_EQ(board.point_count(), 117);
}

TEST(BoardFile, ShippedMrginghamBoard) {
  const CalibrationBoard board = load_board(kBoards / "chessboard-10x10-mrgingham.toml");
  EXPECT_EQ(board.kind, BoardKind::chessboard);
  EXPECT_EQ(board.rows, 10);
  EXPECT_EQ(board.cols, 10);
  // chessboard.10x10.pdf draws 10 mm squares (28.3457 pt); the file asks for a 150 % print.
  EXPECT_DOUBLE_EQ(board.spacing_m, 0.015);
}

TEST(BoardFile, ShippedAprilGrid) {
  const CalibrationBoard board = load_board(kBoards / "aprilgrid-6x8-tag36h11.toml");
  EXPECT_EQ(board.name, "aprilgrid-6x8-tag36h11");
  EXPECT_EQ(board.kind, BoardKind::apriltag_grid);
  EXPECT_EQ(board.rows, 6);
  EXPECT_EQ(board.cols, 8);
  EXPECT_EQ(board.family, "tag36h11");
  EXPECT_DOUBLE_EQ(board.tag_size_m, 0.024);
  EXPECT_NEAR(board.spacing_m, 0.0312, 1e-15);  // tag + gap: the pitch of the tag centres
  EXPECT_EQ(board.first_id, 0);
  // The printed grid with the tags' white rings (1 cell = 3 mm each side) fits A4 landscape
  // (297 x 210 mm) inside a 10 mm printer margin.
  const double cell = board.tag_size_m / 8;
  EXPECT_LE((board.cols - 1) * board.spacing_m + board.tag_size_m + 2 * cell, 0.297 - 0.020);
  EXPECT_LE((board.rows - 1) * board.spacing_m + board.tag_size_m + 2 * cell, 0.210 - 0.020);
}

TEST(BoardFile, PointsFollowMrcalsLayout) {
  const CalibrationBoard board = parse_board(kChess + "inner_corners = [2, 3]\nsquare_m = 0.5\n", "x/my-board.toml");
  EXPECT_EQ(board.name, "my-board");
  // Index r*cols + c holds (c*spacing, r*spacing, 0): x along a row, y down the rows.
  const std::vector<Vec3> expected{{0, 0, 0}, {0.5, 0, 0}, {1, 0, 0}, {0, 0.5, 0}, {0.5, 0.5, 0}, {1, 0.5, 0}};
  EXPECT_EQ(board.points(), expected);
  EXPECT_EQ(board.point(1, 2), (Vec3{1, 0.5, 0}));
}

TEST(BoardFile, AprilGridDefaultsAndPitch) {
  const CalibrationBoard board =
      parse_board(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.012\ndescription = \"x\"\n", "g.toml");
  EXPECT_EQ(board.family, "tag36h11");
  EXPECT_EQ(board.first_id, 0);
  EXPECT_NEAR(board.spacing_m, 0.052, 1e-15);
  const CalibrationBoard other = parse_board(
      kGrid + "tags = [2, 2]\ntag_size_m = 1\ntag_spacing_m = 1\nfamily = \"tag25h9\"\nfirst_id = 31\n", "g.toml");
  EXPECT_EQ(other.family, "tag25h9");
  EXPECT_EQ(other.first_id, 31);  // 31 + 4 ids fit tag25h9's 35 codes
  EXPECT_DOUBLE_EQ(other.spacing_m, 2.0);
}

TEST(BoardFile, UnknownKeyIsNamedWithItsPlace) {
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = 0.02\ncolour = \"red\"\n"),
            "b.toml:4:1: colour: unknown key; allowed keys in the top level: kind, description, inner_corners, square_m");
  EXPECT_EQ(board_error_of(kChess + "tags = [3, 4]\n"),
            "b.toml:2:1: tags: unknown key; allowed keys in the top level: kind, description, inner_corners, "
            "square_m");
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.01\nsquare_m = 0.02\n"),
            "b.toml:5:1: square_m: unknown key; allowed keys in the top level: kind, description, tags, tag_size_m, "
            "tag_spacing_m, family, first_id");
}

TEST(BoardFile, WrongTypesAreNamed) {
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = \"20mm\"\n"),
            "b.toml:3:12: square_m: expected a number > 0 (m), found a string");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = \"9x13\"\nsquare_m = 0.02\n"),
            "b.toml:2:17: inner_corners: expected [rows, cols] of inner corners (squares - 1 each way), two "
            "integers >= 2, found a string");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13.0]\nsquare_m = 0.02\n"),
            "b.toml:2:21: inner_corners[1]: expected an integer in [2, 1000], found a float");
  EXPECT_EQ(board_error_of("kind = 1\n"), "b.toml:1:8: kind: expected one of \"chessboard\", \"apriltag_grid\", \"charuco\", found an integer");
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.01\nfirst_id = 1.5\n"),
            "b.toml:5:12: first_id: expected an integer in [0, 575], found a float");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = 0.02\ndescription = 3\n"),
            "b.toml:4:15: description: expected a string, found an integer");
}

TEST(BoardFile, MissingKeysAreNamed) {
  EXPECT_EQ(board_error_of("inner_corners = [9, 13]\nsquare_m = 0.02\n"),
            "b.toml:1:1: kind: expected one of \"chessboard\", \"apriltag_grid\", \"charuco\", found nothing");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\n"),
            "b.toml:1:1: square_m: expected a number > 0 (m), found nothing");
  EXPECT_EQ(board_error_of(kChess + "square_m = 0.02\n"),
            "b.toml:1:1: inner_corners: expected [rows, cols] of inner corners (squares - 1 each way), two "
            "integers >= 2, found nothing");
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\n"),
            "b.toml:1:1: tag_spacing_m: expected a number >= 0 (m), found nothing");
}

TEST(BoardFile, BadValuesAreNamed) {
  EXPECT_EQ(board_error_of("kind = \"circles\"\n"), "b.toml:1:8: kind: expected one of \"chessboard\", \"apriltag_grid\", \"charuco\", found \"circles\"");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [1, 13]\nsquare_m = 0.02\n"),
            "b.toml:2:18: inner_corners[0]: expected an integer in [2, 1000], found 1");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13, 2]\nsquare_m = 0.02\n"),
            "b.toml:2:17: inner_corners: expected [rows, cols] of inner corners (squares - 1 each way), two integers "
            ">= 2, found 3 items");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [40, 40]\nsquare_m = 0.02\n"),
            "b.toml:2:17: inner_corners: expected at most 1000 points, found 40 x 40");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = 0\n"),
            "b.toml:3:12: square_m: expected a number > 0 (m), found 0.0");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = -0.02\n"),
            "b.toml:3:12: square_m: expected a number > 0 (m), found -0.02");
  EXPECT_EQ(board_error_of(kChess + "inner_corners = [9, 13]\nsquare_m = nan\n"),
            "b.toml:3:12: square_m: expected a finite number, found nan");
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.01\nfamily = \"tag99\"\n"),
            "b.toml:5:10: family: expected one of tag16h5, tag25h9, tag36h10, tag36h11, tagCircle21h7, "
            "tagCircle49h12, tagCustom48h12, tagStandard41h12, tagStandard52h13, found \"tag99\"");
  // tag36h11: 10 cells printed, 8 to the black border, so neighbours need a 2-cell (0.25 x tag) gap.
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.009\n"),
            "b.toml:4:17: tag_spacing_m: expected a gap of at least 0.01 m (2 cells of a tag36h11 tag of 0.04 m, so "
            "that printed tags do not overlap), found 0.009");
  EXPECT_EQ(board_error_of(kGrid + "tags = [3, 4]\ntag_size_m = 0.04\ntag_spacing_m = 0.01\nfirst_id = 576\n"),
            "b.toml:5:12: first_id: expected an integer in [0, 575], found 576");  // 576 + 12 > 587 ids
  EXPECT_EQ(board_error_of(kGrid + "tags = [6, 6]\ntag_size_m = 0.04\ntag_spacing_m = 0.02\nfamily = \"tag16h5\"\n"),
            "b.toml:2:8: tags: expected at most 30 tags (family tag16h5 has 30 ids), found 6 x 6");
}

TEST(BoardFile, SyntaxErrorAndUnreadableFile) {
  EXPECT_EQ(board_error_of(kChess + "square_m = \n").rfind("b.toml:2:", 0), 0u) << board_error_of(kChess + "square_m = \n");
  EXPECT_NE(board_error_of(kChess + "square_m = \n").find("TOML syntax error"), std::string::npos);

  const fs::path dir = scratch_dir("board-file");
  try {
    load_board(dir / "absent.toml");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const BoardError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "absent.toml").string() + ": cannot read board file: No such file or directory");
  }
  EXPECT_THROW(load_board(dir), BoardError);
  // A file's messages carry its path.
  std::ofstream(dir / "bad.toml") << kChess << "inner_corners = [9, 13]\n";
  try {
    load_board(dir / "bad.toml");
    ADD_FAILURE() << "no error for a board without square_m";
  } catch (const BoardError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "bad.toml").string() + ":1:1: square_m: expected a number > 0 (m), found nothing");
  }
  remove_scratch(dir);
}

}  // namespace
}  // namespace arpipe::calib
