// Finds a calibration board in an 8-bit grey image: chessboards by mrgingham where it applies
// (square N x N boards) and OpenCV's findChessboardCornersSB otherwise; AprilTag grids by
// libapriltag, each tag's centre from the homography of its refined corners.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"

namespace arpipe::calib {

class BoardDetector {
 public:
  explicit BoardDetector(const CalibrationBoard& board);
  ~BoardDetector();
  BoardDetector(const BoardDetector&) = delete;
  BoardDetector& operator=(const BoardDetector&) = delete;

  // The board in this image, or nullopt when it is not found (too few points, wrong geometry).
  // grey: width x height bytes, rows `stride` apart. Never throws. Safe to call from one thread at
  // a time per detector (make one detector per thread).
  std::optional<BoardObservation> detect(const unsigned char* grey, int width, int height, size_t stride,
                                         const std::string& image_name) const;

  // Which method detect() uses for this board: "mrgingham", "findChessboardCornersSB", "apriltag".
  const std::string& method() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe::calib
