// One image's view of the calibration board: the pixel of every observed point (or none), in the
// board's point order, with the weight mrcal gives it.
#pragma once

#include <string>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe::calib {

struct BoardObservation {
  std::string image;          // file name or "recording frame N": what messages and reports show
  int width = 0;              // size of the image it came from
  int height = 0;
  // One entry per board point (CalibrationBoard::point order). weight <= 0 marks a point that was
  // not seen (partial board) or, after the solve, an outlier. Weight is 1/(relative noise):
  // 1 at full resolution, 2^-level for a corner found at pyramid level `level`.
  std::vector<Vec2> pixels;
  std::vector<double> weights;
  std::string detector;       // "mrgingham", "findChessboardCornersSB", "findChessboardCorners", "apriltag", ...
  // Chessboards: how each corner the detector found got its place. The X-junction model fit; else
  // (the fit failed, or moved it too far) cornerSubPix; the finder's own only without refinement;
  // or dropped (weight -1: cornerSubPix found no junction near the finder's place, or no place
  // inside the image), never the whole view for one corner while 60 % of the board is left.
  struct Refinements {
    int model_fit = 0;
    int corner_subpix = 0;
    int detector = 0;
    int dropped = 0;
  } refined;

  int seen_count() const;
};

}  // namespace arpipe::calib
