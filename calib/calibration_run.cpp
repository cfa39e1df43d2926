#include "calib/calibration_run.h"

namespace arpipe::calib {

CalibrationRun run_calibration(const CalibrationImages& images, const CalibrationBoard& board,
                               const SolveOptions& options, int threads, const CalibrationRunProgress& progress) {
  const auto detection_progress = [&progress](int pass) -> std::function<void(int, int)> {
    if (!progress.detection) return {};
    return [&progress, pass](int done, int total) { progress.detection(pass, done, total); };
  };
  DetectionSet found = detect_boards(images, board, threads, detection_progress(1));
  CalibrationResult result = solve_calibration(board, found.views, found.width, found.height, options, progress.solve);
  if (board.kind != BoardKind::apriltag_grid) return {std::move(found), std::move(result), std::nullopt};

  const double first_rms = result.rms_per_point_px;
  found = detect_boards(images, board, threads, detection_progress(2), &result.model);
  CalibrationResult second = solve_calibration(board, found.views, found.width, found.height, options, progress.solve);
  return {std::move(found), std::move(second), first_rms};
}

}  // namespace arpipe::calib
