// The calibration solve: seeding in C++ (pinhole guess, one PnP per board view) and mrcal's staged
// optimisation (board poses, then the core intrinsics, then the full lens model with regularisation
// and outlier rejection, then the board's warp), for PINHOLE, OPENCV4/5/8 and SPLINED_STEREOGRAPHIC.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"

namespace arpipe::calib {

// The data cannot give a calibration; what() says why and what to do (more views, tilt the board...).
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SolveOptions {
  // An mrcal lens-model name. "LENSMODEL_SPLINED_STEREOGRAPHIC" without a configuration gets one
  // chosen from the image size and the field of view the seed finds (order 3, Nx:Ny = aspect).
  std::string lensmodel = "LENSMODEL_OPENCV8";
  double focal_guess_px = 0;      // 0: guess from the views (PnP over candidate focal lengths)
  bool optimize_board_warp = true;
  bool reject_outliers = true;
  // mrcal's regularisation (distortions toward 0, the centre toward the image's middle). Its weight
  // is fixed for corners about 1 px off (mrcal 2.2, mrcal.c: normal_pixel_error = 1.0), not scaled
  // by the actual noise, so it biases the lens by a constant few thousandths of a pixel: nothing
  // against real corners (0.01-0.3 px), the floor of a synthetic solve at 0.001 px. Off only for
  // such studies (`arpipe bench calib-solve --no-regularization`); a real calibration keeps it.
  bool regularize = true;
  bool verbose = false;           // mrcal's solver prints its progress to stderr
};

struct SolveStage {
  std::string name;               // "board poses", "core intrinsics", "full model", "board warp"
  double rms_per_coordinate_px = 0;
  int outliers = 0;
  double seconds = 0;
};

struct SolvedProblem;             // mrcal's arrays at the solution, for the uncertainty (opaque)

struct CalibrationResult {
  CameraModel model;
  CalibrationBoard board;
  // Every view that entered the solve, in input order, with outliers marked (weight < 0 where the
  // input had weight > 0).
  std::vector<BoardObservation> observations;
  std::vector<SE3> T_cam_board;                 // per view
  double board_warp_x_m = 0;                    // mrcal's calobject_warp: board bulge along x and y
  double board_warp_y_m = 0;
  // residuals[view][point] = projected - observed, pixels, unweighted; NaN for points not seen.
  std::vector<std::vector<Vec2>> residuals_px;
  // mrcal's figure: sqrt(sum of squared x and y residuals / number of coordinates), weighted,
  // regularisation included. OpenCV's calibrateCamera reports the per-point figure, ~sqrt(2) larger.
  double rms_per_coordinate_px = 0;
  double rms_per_point_px = 0;                  // sqrt(mean |residual|^2) over inlier points, unweighted
  int outlier_count = 0;
  int inlier_count = 0;
  std::vector<SolveStage> stages;
  double seconds = 0;
  std::shared_ptr<const SolvedProblem> problem;
};

// Progress: (stage index, stage count, stage name) before each stage.
using SolveProgress = std::function<void(int, int, const std::string&)>;

// observations: views of `board` from one camera, all from images of width x height (the caller
// checks sizes). Throws CalibrationError with advice when there are too few views (< 4 with a seen
// board), the seed fails, or mrcal fails; throws CameraModelError for an unknown lens model.
CalibrationResult solve_calibration(const CalibrationBoard& board, const std::vector<BoardObservation>& observations,
                                    int width, int height, const SolveOptions& options,
                                    const SolveProgress& progress = {});

}  // namespace arpipe::calib
