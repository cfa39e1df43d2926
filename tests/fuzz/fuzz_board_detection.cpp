// libFuzzer target: the calibration board detectors on hostile pictures (calib BoardDetector::detect:
// the chessboard finders' cascade with cornerSubPix, the X-junction fit and the classic finder's
// grid check; mrgingham; the AprilTag grid; ChArUco). A picture comes from any camera or image file,
// so detect() must never throw or crash, whatever the pixels.
// Input: tests/fuzz/fuzz_boards.h (DetectionInput); tests/fuzz/make_seeds.cpp writes seeds with
// each board drawn.
#include <cstddef>
#include <cstdint>

#include "calib/board_detector.h"
#include "calib/calibration_board.h"
#include "core/geometry/camera_model.h"
#include "tests/fuzz/fuzz_boards.h"

namespace {

using arpipe::calib::BoardDetector;
using arpipe::calib::CalibrationBoard;

const BoardDetector& detector(size_t which) {
  static const std::vector<CalibrationBoard> boards = [] {
    std::vector<CalibrationBoard> out;
    for (const char* text : arpipe::fuzz::kDetectionBoards) out.push_back(arpipe::calib::parse_board(text, "fuzz-board-detection.toml"));
    return out;
  }();
  static const std::vector<const BoardDetector*> detectors = [] {
    std::vector<const BoardDetector*> out;
    for (const CalibrationBoard& board : boards) out.push_back(new BoardDetector(board));  // kept for the process
    return out;
  }();
  return *detectors[which];
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto in = arpipe::fuzz::decode_detection_input(data, size);
  if (!in) return 0;
  const BoardDetector& found = detector(in->board);
  (void)found.detect(in->grey.data(), in->width, in->height, size_t(in->width), "fuzz picture");
  if (in->with_lens) {
    const auto lens =
        arpipe::CameraModel::pinhole(in->width, in->width, (in->width - 1) / 2.0, (in->height - 1) / 2.0, in->width, in->height);
    (void)found.detect(in->grey.data(), in->width, in->height, size_t(in->width), "fuzz picture", lens);
  }
  return 0;
}
