// The board-detection fuzz target's boards and input format, shared by the target
// (fuzz_board_detection.cpp), its seeds (make_seeds.cpp) and the seeds' test
// (tests/calib/board_detection_seeds_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

namespace arpipe::fuzz {

// Small boards: each fits a picture of 8 to 128 pixels a side.
inline constexpr const char* kDetectionBoards[] = {
    "kind = \"chessboard\"\ninner_corners = [3, 4]\nsquare_m = 0.02\n",
    "kind = \"chessboard\"\ninner_corners = [4, 4]\nsquare_m = 0.02\n",  // square: mrgingham first
    "kind = \"apriltag_grid\"\ntags = [2, 2]\ntag_size_m = 0.024\ntag_spacing_m = 0.0072\nfamily = \"tag36h11\"\n"
    "first_id = 0\n",
    "kind = \"charuco\"\nsquares = [4, 5]\nsquare_m = 0.02\nmarker_m = 0.015\ndictionary = \"DICT_4X4_50\"\n",
};

// One input: byte 0 picks the board (mod 4), bytes 1 and 2 the width and height (8 + byte % 121),
// byte 3 bit 0 asks for a second detection through a pinhole lens; the rest are the grey pixels,
// repeated to fill the picture (zero when there are none).
struct DetectionInput {
  size_t board = 0;
  int width = 0, height = 0;
  bool with_lens = false;
  std::vector<unsigned char> grey;
};

// nullopt under 4 bytes.
inline std::optional<DetectionInput> decode_detection_input(const uint8_t* data, size_t size) {
  if (size < 4) return std::nullopt;
  DetectionInput in;
  in.board = data[0] % std::size(kDetectionBoards);
  in.width = 8 + data[1] % 121;
  in.height = 8 + data[2] % 121;
  in.with_lens = (data[3] & 1) != 0;
  in.grey.assign(size_t(in.width) * size_t(in.height), 0);
  if (size > 4)
    for (size_t i = 0; i < in.grey.size(); ++i) in.grey[i] = data[4 + i % (size - 4)];
  return in;
}

// The input that decodes to exactly this picture (width and height 8 to 128, grey row by row).
inline std::string encode_detection_input(size_t board, int width, int height, bool with_lens,
                                          const std::vector<unsigned char>& grey) {
  std::string bytes{char(board), char(width - 8), char(height - 8), char(with_lens ? 1 : 0)};
  bytes.append(grey.begin(), grey.end());
  return bytes;
}

}  // namespace arpipe::fuzz
