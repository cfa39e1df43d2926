// The board-detection fuzz target's seeds (tests/fuzz/corpus/fuzz_board_detection, written by
// tests/fuzz/make_seeds.cpp) each hold a board its detector finds whole, so that mutations start
// from pictures that reach the corner refinement, the grid check and the ChArUco and AprilTag paths.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "calib/board_detector.h"
#include "calib/calibration_board.h"
#include "tests/fuzz/fuzz_boards.h"

namespace arpipe::calib {
namespace {

namespace fs = std::filesystem;

TEST(BoardDetectionSeeds, EachSeedHoldsABoardItsDetectorFinds) {
  const fs::path corpus = fs::path(ARPIPE_SOURCE_DIR) / "tests/fuzz/corpus/fuzz_board_detection";
  for (size_t which = 0; which < std::size(fuzz::kDetectionBoards); ++which) {
    const fs::path seed = corpus / ("board-" + std::to_string(which));
    std::ifstream file(seed, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
    const auto in = fuzz::decode_detection_input(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    ASSERT_TRUE(in.has_value()) << seed;
    ASSERT_EQ(size_t(bytes[0]), which) << seed;
    ASSERT_EQ(bytes.size(), 4 + in->grey.size()) << seed;  // the picture whole, nothing repeated
    const CalibrationBoard board = parse_board(fuzz::kDetectionBoards[which], "seed.toml");
    const BoardDetector detector(board);
    const auto found = detector.detect(in->grey.data(), in->width, in->height, size_t(in->width), seed.string());
    ASSERT_TRUE(found.has_value()) << seed << " (" << in->width << "x" << in->height << ")";
    EXPECT_EQ(found->seen_count(), board.point_count()) << seed;
  }
}

}  // namespace
}  // namespace arpipe::calib
