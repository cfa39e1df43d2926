// The small calibration boards of the board-detection fuzz target (fuzz_board_detection.cpp) and its
// seeds (make_seeds.cpp): each fits a picture of 8 to 128 pixels a side.
#pragma once

namespace arpipe::fuzz {

inline constexpr const char* kDetectionBoards[] = {
    "kind = \"chessboard\"\ninner_corners = [3, 4]\nsquare_m = 0.02\n",
    "kind = \"chessboard\"\ninner_corners = [4, 4]\nsquare_m = 0.02\n",  // square: mrgingham first
    "kind = \"apriltag_grid\"\ntags = [2, 2]\ntag_size_m = 0.024\ntag_spacing_m = 0.0072\nfamily = \"tag36h11\"\n"
    "first_id = 0\n",
    "kind = \"charuco\"\nsquares = [4, 5]\nsquare_m = 0.02\nmarker_m = 0.015\ndictionary = \"DICT_4X4_50\"\n",
};

}  // namespace arpipe::fuzz
