// Board observations written as mrcal's corners cache (corners.vnl), so mrcal's own tools
// (mrcal-calibrate-cameras --corners-cache ... --corners-cache-has-weights) can run on our corners.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "calib/board_observation.h"
#include "calib/calibration_board.h"

namespace arpipe::calib {

// The vnlog text: the legend "# filename x y weight", then board.rows * board.cols rows per view in
// mrcal's pool order (row-major over the board's points), "filename - - -" for a point not seen or
// rejected (weight <= 0). The filename column is each view's image name, or file_names[view] when
// given; mrcal splits rows on whitespace and matches its image globs against this column, so
// whitespace in a name becomes '_' ("rec frame 7" -> "rec_frame_7"). Throws std::invalid_argument on
// a view whose point count does not match the board.
std::string corners_vnl(const std::vector<BoardObservation>& views, const CalibrationBoard& board,
                        const std::vector<std::string>& file_names = {});

// Writes corners_vnl() to `path`. Throws std::runtime_error naming the file when it cannot be written.
void write_corners_vnl(const std::filesystem::path& path, const std::vector<BoardObservation>& views,
                       const CalibrationBoard& board, const std::vector<std::string>& file_names = {});

}  // namespace arpipe::calib
