// A calibration board as described by configs/boards/*.toml: what is printed, and where its
// observed points (the ones mrcal's solve sees) sit in the board's own frame.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/config/choice_names.h"
#include "core/geometry/vec.h"

namespace arpipe::calib {

// Bad board file; what() reads "FILE:LINE:COL: key: expected ..., found ..." (core/config/toml_section.h).
class BoardError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class BoardKind {
  chessboard,    // observed points: the inner corners
  apriltag_grid, // observed points: the tag centres (see docs/CALIBRATION.md for why not the corners)
  charuco        // ChArUco (OpenCV's aruco module): observed points the inner corners, each named by its id
};
inline constexpr ChoiceName<BoardKind> kBoardKindNames[] = {{"chessboard", BoardKind::chessboard},
                                                           {"apriltag_grid", BoardKind::apriltag_grid},
                                                           {"charuco", BoardKind::charuco}};

// OpenCV's predefined ArUco dictionaries a ChArUco board may use (cv::aruco::PREDEFINED_DICTIONARY_NAME),
// by name ("DICT_5X5_100") and OpenCV's number for it.
struct ArucoDictionaryName {
  const char* name;
  int id;
};
const std::vector<ArucoDictionaryName>& aruco_dictionary_names();

struct CalibrationBoard {
  std::string name;         // from the file's stem
  BoardKind kind = BoardKind::chessboard;
  // The grid of observed points, in mrcal's terms height_n x width_n: for a chessboard the inner
  // corners (squares - 1 each way), for an AprilTag grid the tags.
  int rows = 0;
  int cols = 0;
  double spacing_m = 0;     // between neighbouring observed points: square edge, or tag pitch
  // AprilTag grid only.
  std::string family;       // libapriltag family name, e.g. "tag36h11"
  double tag_size_m = 0;    // black-border edge of one tag
  int first_id = 0;         // id of the tag at row 0, col 0; ids run along rows: id = first_id + row*cols + col
  // ChArUco only: (rows + 1) x (cols + 1) squares of spacing_m, the top-left one dark, a marker of
  // marker_m in each light square; the inner corner (row, col) has OpenCV's ChArUco id row*cols + col.
  double marker_m = 0;
  std::string dictionary;   // "DICT_5X5_100", ...
  int dictionary_id = 0;    // OpenCV's number for it (cv::aruco::PREDEFINED_DICTIONARY_NAME)

  int point_count() const { return rows * cols; }
  // Point (row r, col c) at index r*cols + c sits at (c*spacing, r*spacing, 0): mrcal's layout,
  // x along a row, y down the rows (mrcal.c, "calibration object" geometry).
  Vec3 point(int row, int col) const { return {col * spacing_m, row * spacing_m, 0.0}; }
  std::vector<Vec3> points() const;
};

// Reads a board file. Keys (all required unless noted):
//   kind = "chessboard" | "apriltag_grid"
//   chessboard:    inner_corners = [rows, cols], square_m
//   apriltag_grid: tags = [rows, cols], tag_size_m, tag_spacing_m (gap between tags), family
//                  (default "tag36h11"), first_id (default 0)
//   charuco:       squares = [rows, cols] (of squares; the points are the (rows-1) x (cols-1) inner
//                  corners), square_m, marker_m (< square_m), dictionary (an OpenCV DICT_* name with
//                  at least one code per light square)
//   description (optional string)
// Unknown keys are errors. Throws BoardError.
CalibrationBoard load_board(const std::filesystem::path& path);
CalibrationBoard parse_board(const std::string& text, const std::string& source_name);

}  // namespace arpipe::calib
