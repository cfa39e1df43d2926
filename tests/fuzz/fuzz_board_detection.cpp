// libFuzzer target: the calibration board detectors on hostile pictures (calib BoardDetector::detect:
// the chessboard finders' cascade with cornerSubPix, the X-junction fit and the classic finder's
// grid check; mrgingham; the AprilTag grid; ChArUco). A picture comes from any camera or image file,
// so detect() must never throw or crash, whatever the pixels.
// Input: byte 0 picks the board (mod 4), bytes 1 and 2 the width and height (8 + byte % 121), byte
// 3 bit 0 detects a second time through a pinhole lens; the rest are the grey pixels, repeated to
// fill the picture (zero when there are none). tests/fuzz/make_seeds.cpp writes seeds with each
// board drawn.
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

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
  if (size < 4) return 0;
  const size_t which = data[0] % std::size(arpipe::fuzz::kDetectionBoards);
  const int width = 8 + data[1] % 121, height = 8 + data[2] % 121;
  const bool with_lens = (data[3] & 1) != 0;
  std::vector<unsigned char> grey(size_t(width) * size_t(height), 0);
  if (size > 4)
    for (size_t i = 0; i < grey.size(); ++i) grey[i] = data[4 + i % (size - 4)];
  const BoardDetector& found = detector(which);
  (void)found.detect(grey.data(), width, height, size_t(width), "fuzz picture");
  if (with_lens) {
    const auto lens = arpipe::CameraModel::pinhole(width, width, (width - 1) / 2.0, (height - 1) / 2.0, width, height);
    (void)found.detect(grey.data(), width, height, size_t(width), "fuzz picture", lens);
  }
  return 0;
}
