// mrcal's optimization_inputs for a solved calibration: the arrays arpipe gave mrcal_optimize at the
// solution, stored in the .cameramodel exactly as mrcal 2.2's Python writer stores them, for its tools.
#pragma once

#include <filesystem>
#include <string>

#include "calib/calibration_solver.h"

namespace arpipe::calib {

// The value of the model's 'optimization_inputs' key: the dict mrcal.optimize() takes (intrinsics,
// frames_rt_toref, observations_board with the outliers' weights negated, calobject_warp, the final
// stage's do_optimize_* / do_apply_* flags, imagepaths, ...) as a numpy .npz, base-85 encoded
// (mrcal/cameramodel.py _serialize_optimization_inputs). Throws std::logic_error when the result
// carries no solved problem.
std::string optimization_inputs_base85(const CalibrationResult& result);

// The model's text (CameraModel::to_string: intrinsics at %.17g) with 'icam_intrinsics': 0 and
// 'optimization_inputs' added, as mrcal.cameramodel(optimization_inputs=..., icam_intrinsics=0)
// writes them.
std::string model_text_with_optimization_inputs(const CalibrationResult& result);

// Writes that text to path (through a temporary file and a rename). Throws CameraModelError naming
// the file when it cannot be written.
void save_model_with_optimization_inputs(const CalibrationResult& result, const std::filesystem::path& path);

}  // namespace arpipe::calib
