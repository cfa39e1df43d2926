// Finds a calibration board in an 8-bit grey image: chessboards by a cascade of finders (mrgingham
// on square N x N boards, OpenCV's findChessboardCornersSB with two sets of flags, then the classic
// findChessboardCorners), the first that finds the whole board wins; AprilTag grids by
// libapriltag, each tag's centre from the homography of its refined corners; ChArUco boards by
// OpenCV's aruco module (the markers name the corners), each corner placed by the X-junction fit.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

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

// The chessboard finders. Why this order (measured on OpenCV's 13 photographs of a 9 x 6 board,
// docs/CALIBRATION.md "Finding the board"): SB with EXHAUSTIVE missed 3 that SB with
// NORMALIZE_IMAGE and the classic finder find; the classic finder found all 13 but, on a board cut
// off by the image's edge, can take seconds to give up, so it comes last.
enum class ChessboardFinder {
  mrgingham,      // square boards only (mrgingham's own CLI preprocessing)
  sb_exhaustive,  // findChessboardCornersSB, CALIB_CB_EXHAUSTIVE
  sb_normalized,  // findChessboardCornersSB, CALIB_CB_NORMALIZE_IMAGE
  classic,        // findChessboardCorners, ADAPTIVE_THRESH | NORMALIZE_IMAGE | FAST_CHECK
};
// The name BoardObservation::detector gets ("findChessboardCornersSB (NORMALIZE_IMAGE)", ...).
const char* chessboard_finder_name(ChessboardFinder finder);
// Every finder that applies to the board, in the order above (mrgingham only on square boards).
std::vector<ChessboardFinder> chessboard_finders(const CalibrationBoard& board);

class BoardDetector {
 public:
  // Throws BoardError when the board's tag family is not one libapriltag knows. `finders`: the
  // chessboard finders to try, in order (empty: chessboard_finders(board)); a benchmark names one.
  explicit BoardDetector(const CalibrationBoard& board, CornerRefinement refinement = CornerRefinement::model_fit,
                         std::vector<ChessboardFinder> finders = {});
  ~BoardDetector();
  BoardDetector(const BoardDetector&) = delete;
  BoardDetector& operator=(const BoardDetector&) = delete;

  // The board in this image, or nullopt when it is not found (too few points, wrong geometry).
  // grey: width x height bytes, rows `stride` apart. Never throws. Safe to call from one thread at
  // a time per detector (make one detector per thread).
  // Chessboards: the finders in order until one finds the whole board (BoardObservation::detector
  // says which); cornerSubPix and the model fit refine each corner (a corner cornerSubPix cannot
  // place is dropped, one the fit cannot place keeps cornerSubPix's), and on the classic finder's
  // boards a corner off its neighbours' homography is dropped (grid_consistency.h);
  // BoardObservation::refined counts them. The points come in one canonical order: the board seen from its printed side (the
  // board frame right-handed with z away from the camera), rows running as nearly left to right
  // in the image as the board's symmetry allows (ChArUco corners and AprilTag centres: by their
  // ids, which fix the order). A point that was not seen has weight -1 and pixel (-1, -1).
  std::optional<BoardObservation> detect(const unsigned char* grey, int width, int height, size_t stride,
                                         const std::string& image_name) const;
  // The same with the lens known approximately, from a first solve. It matters for AprilTag grids
  // only: a tag's centre is then found where the lens really puts it (without the lens it is off
  // by the lens's bend over the tag: 0.1-0.4 px for a wide lens). nullopt when the lens's image
  // size is not the image's.
  std::optional<BoardObservation> detect(const unsigned char* grey, int width, int height, size_t stride,
                                         const std::string& image_name, const CameraModel& lens) const;

  // The first method detect() tries for this board: "mrgingham", "findChessboardCornersSB", "apriltag",
  // "charuco".
  const std::string& method() const;

 private:
  std::optional<BoardObservation> find(const unsigned char* grey, int width, int height, size_t stride,
                                       const std::string& image_name, const CameraModel* lens) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe::calib
