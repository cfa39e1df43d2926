// Finds a calibration board in an 8-bit grey image: chessboards by mrgingham where it applies
// (square N x N boards) and OpenCV's findChessboardCornersSB otherwise; AprilTag grids by
// libapriltag, each tag's centre from the homography of its refined corners.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"

namespace arpipe {
class CameraModel;
}

namespace arpipe::calib {

// How chessboard corners are refined after the board is found (AprilTag grids ignore it).
enum class CornerRefinement {
  none,           // the finder's own corners (mrgingham's or findChessboardCornersSB's)
  corner_subpix,  // OpenCV's cornerSubPix
  model_fit,      // cornerSubPix, then the X-junction model fit (calib/chessboard_corner_fit.h)
};

class BoardDetector {
 public:
  // Throws BoardError when the board's tag family is not one libapriltag knows.
  explicit BoardDetector(const CalibrationBoard& board, CornerRefinement refinement = CornerRefinement::model_fit);
  ~BoardDetector();
  BoardDetector(const BoardDetector&) = delete;
  BoardDetector& operator=(const BoardDetector&) = delete;

  // The board in this image, or nullopt when it is not found (too few points, wrong geometry).
  // grey: width x height bytes, rows `stride` apart. Never throws. Safe to call from one thread at
  // a time per detector (make one detector per thread).
  // Chessboards: mrgingham finds a square board, findChessboardCornersSB a non-square one or a
  // square one mrgingham missed (BoardObservation::detector says which); cornerSubPix refines the
  // corners. The points come in one canonical order: the board seen from its printed side (the
  // board frame right-handed with z away from the camera), rows running as nearly left to right
  // in the image as the board's symmetry allows. A point that was not seen has weight -1 and
  // pixel (-1, -1).
  std::optional<BoardObservation> detect(const unsigned char* grey, int width, int height, size_t stride,
                                         const std::string& image_name) const;
  // The same with the lens known approximately, from a first solve. It matters for AprilTag grids
  // only: a tag's centre is then found where the lens really puts it (without the lens it is off
  // by the lens's bend over the tag: 0.1-0.4 px for a wide lens). nullopt when the lens's image
  // size is not the image's.
  std::optional<BoardObservation> detect(const unsigned char* grey, int width, int height, size_t stride,
                                         const std::string& image_name, const CameraModel& lens) const;

  // Which method detect() uses for this board: "mrgingham", "findChessboardCornersSB", "apriltag".
  const std::string& method() const;

 private:
  std::optional<BoardObservation> find(const unsigned char* grey, int width, int height, size_t stride,
                                       const std::string& image_name, const CameraModel* lens) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe::calib
