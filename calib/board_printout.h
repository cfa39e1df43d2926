// The printable picture of a calibration board: what to print so that the board file describes
// the paper exactly (square or tag sizes at the chosen resolution), with a white margin.
#pragma once

#include <filesystem>

#include "calib/calibration_board.h"

namespace arpipe::calib {

struct PrintedBoard {
  int width_px = 0;
  int height_px = 0;
  double width_m = 0;   // printed size, margins included
  double height_m = 0;
};

// Writes a grey PNG with `dots_per_inch` pixels per printed inch (print it at that resolution, at
// 100 %, not fitted to the page), with one square (chessboard, ChArUco) or one tag gap plus a border cell
// (AprilTag grid) of white margin.
// Throws BoardError naming the file when it cannot be written or the family is unknown.
PrintedBoard write_board_png(const CalibrationBoard& board, const std::filesystem::path& png, double dots_per_inch);

}  // namespace arpipe::calib
