// A picture of the calibration residuals a person can look at: every observed point at its place
// in the image, its residual drawn as a magnified arrow coloured by size, outliers as red crosses,
// and the cells of the image that no observation reached shaded.
#pragma once

#include <filesystem>

#include "calib/calibration_solver.h"

namespace arpipe::calib {

// Writes a PNG of the image's size (at least 640 wide: small images are scaled up). Throws
// CalibrationInputError naming the file when it cannot be written.
void write_residual_image(const std::filesystem::path& png, const CalibrationResult& result);

}  // namespace arpipe::calib
