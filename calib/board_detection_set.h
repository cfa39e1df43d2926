// Detection over a whole image set: every image searched for the board (in parallel), sizes
// checked to agree, and a clear error with advice when the board is found nowhere.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"
#include "calib/calibration_images.h"

namespace arpipe {
class CameraModel;
}

namespace arpipe::calib {

struct DetectionSet {
  std::vector<BoardObservation> views;        // images where the board was found, in image order
  std::vector<std::string> without_board;     // the others
  int width = 0;                              // every image's size
  int height = 0;
  int images = 0;
};

// progress(done, total) after each image, from the calling thread. Throws CalibrationInputError:
// an unreadable image (named); images of different sizes (two named, with their sizes); the board
// found in none of the images (with what the images seem to show instead when another chessboard
// size is found in them, the usual mistake being squares counted instead of inner corners).
// lens: a lens known approximately (a first solve); AprilTag grids then place each tag's centre
// where that lens puts it (BoardDetector::detect with a lens). Chessboards ignore it.
DetectionSet detect_boards(const CalibrationImages& images, const CalibrationBoard& board, int threads,
                           const std::function<void(int, int)>& progress = {}, const CameraModel* lens = nullptr);

}  // namespace arpipe::calib
