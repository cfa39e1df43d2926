// libFuzzer target: calibration board files (calib parse_board, the text behind load_board).
// Bad input must be a BoardError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "calib/calibration_board.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)arpipe::calib::parse_board(text, "fuzz-board.toml");
  } catch (const arpipe::calib::BoardError&) {
  }
  return 0;
}
