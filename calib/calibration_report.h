// What a calibration is worth, in numbers a person can judge: residuals overall and per image,
// outliers, the images that fit worst, how much of the image the observations cover, and the
// projection uncertainty at the centre and corners. Written as text (for the terminal) and JSON.
#pragma once

#include <string>
#include <vector>

#include "calib/calibration_solver.h"
#include "calib/projection_uncertainty.h"

namespace arpipe::calib {

struct ImageResidual {
  std::string image;
  int points = 0;             // inlier points
  int outliers = 0;
  double rms_px = 0;          // per point (|residual| over its x and y), inliers, unweighted
  double max_px = 0;
  std::string detector;       // the finder that found the board in it (BoardObservation::detector)
  BoardObservation::Refinements refined;  // chessboards: how its corners were placed
};

// The image cut into cols x rows cells; a cell is covered when at least one inlier point fell in it.
struct CoverageGrid {
  int cols = 8;
  int rows = 6;
  std::vector<int> points;    // per cell, row-major
  double covered_fraction = 0;
  // Inlier points within this many pixels of the nearest image corner (the farthest of the four):
  // a lens model is only known where it was observed, and the corners bend most.
  double worst_corner_gap_px = 0;
};

struct CalibrationReport {
  std::string lensmodel;
  std::vector<double> intrinsics;
  int width = 0;
  int height = 0;
  int images_total = 0;                       // given to the command
  std::vector<std::string> images_without_board;
  int views_used = 0;
  double rms_per_coordinate_px = 0;           // mrcal's figure (see CalibrationResult)
  double rms_per_point_px = 0;                // OpenCV's kind of figure
  int inliers = 0;
  int outliers = 0;
  double board_warp_x_m = 0;
  double board_warp_y_m = 0;
  std::vector<ImageResidual> per_image;       // in view order
  std::vector<int> worst_images;              // indices into per_image, worst RMS first (up to 5)
  CoverageGrid coverage;
  std::vector<PixelUncertainty> uncertainty;  // centre, then the four corners; at infinity
  // The same on a grid over the whole image (9 x 7 points, corners and edges included, row-major):
  // where the model is known well and where it is extrapolated.
  int uncertainty_grid_cols = 9;
  int uncertainty_grid_rows = 7;
  std::vector<PixelUncertainty> uncertainty_grid;
  std::vector<SolveStage> stages;
  double solve_seconds = 0;
  std::vector<std::string> advice;            // things to fix before trusting the model
};

// images_total and images_without_board come from the detection step.
CalibrationReport make_report(const CalibrationResult& result, int images_total,
                              std::vector<std::string> images_without_board);
std::string report_text(const CalibrationReport& report);
std::string report_json(const CalibrationReport& report);  // one JSON object, pretty-printed

}  // namespace arpipe::calib
