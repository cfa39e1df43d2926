// Projection uncertainty of a solved calibration, mrcal's formula (uncertainty.org, mrcal 2.2) in
// C++: the observation noise propagated through the solver's Jacobian to the intrinsics and the
// board poses, then to the pixel a fixed world point projects to. mrcal 2.2 has it only in Python.
#pragma once

#include <vector>

#include "calib/calibration_solver.h"
#include "core/geometry/vec.h"

namespace arpipe::calib {

struct PixelUncertainty {
  Vec2 pixel;                       // where the query point projects
  double distance_m = 0;            // 0 = at infinity
  double worst_direction_stdev_px = 0;  // sqrt of the larger eigenvalue of the 2x2 covariance
  double rms_stdev_px = 0;              // sqrt(trace / 2)
  double covariance[2][2] = {};
};

// For each pixel: the point at distance_m along its ray (or at infinity when 0), seen by the
// solved camera. observed_pixel_stdev <= 0: estimated from the solve's residuals as mrcal does.
std::vector<PixelUncertainty> projection_uncertainty(const CalibrationResult& result, const std::vector<Vec2>& pixels,
                                                     double distance_m, double observed_pixel_stdev = 0);

}  // namespace arpipe::calib
