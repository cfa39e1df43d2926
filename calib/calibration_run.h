// The whole calibration of one camera from an image set: the board found in every image, the lens
// solved with mrcal, and for AprilTag grids a second pass that finds the tags' centres through the
// first solve's lens and solves again.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "calib/board_detection_set.h"
#include "calib/calibration_solver.h"

namespace arpipe::calib {

struct CalibrationRun {
  DetectionSet found;          // the detection the final solve used
  CalibrationResult result;
  // AprilTag grids: the first solve's RMS per point, from centres placed without the lens.
  std::optional<double> first_pass_rms_per_point_px;
};

struct CalibrationRunProgress {
  // pass: 1, or 2 for an AprilTag grid's pass with the lens; called from the calling thread.
  std::function<void(int pass, int done, int total)> detection;
  SolveProgress solve;
};

// Throws what detect_boards and solve_calibration throw.
// Why a second pass for AprilTag grids: a tag's centre is where its diagonals cross only under a
// pinhole; through a wide lens the crossing is off by 0.1 px RMS (up to 0.4 px near the image edge:
// docs/CALIBRATION.md), a bias the solve cannot tell from the lens. The first solve's lens is close
// enough to remove it; chessboard corners need no lens.
CalibrationRun run_calibration(const CalibrationImages& images, const CalibrationBoard& board,
                               const SolveOptions& options, int threads, const CalibrationRunProgress& progress = {});

}  // namespace arpipe::calib
