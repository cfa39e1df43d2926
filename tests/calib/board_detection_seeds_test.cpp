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
    std::ifstream in(seed, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    ASSERT_GT(bytes.size(), 4u) << seed;
    ASSERT_EQ(size_t(bytes[0]), which) << seed;
    const int width = 8 + (unsigned char)bytes[1] % 121, height = 8 + (unsigned char)bytes[2] % 121;
    ASSERT_EQ(bytes.size(), 4 + size_t(width) * size_t(height)) << seed;
    const CalibrationBoard board = parse_board(fuzz::kDetectionBoards[which], "seed.toml");
    const BoardDetector detector(board);
    const auto found = detector.detect(reinterpret_cast<const unsigned char*>(bytes.data()) + 4, width, height,
                                       size_t(width), seed.string());
    ASSERT_TRUE(found.has_value()) << seed << " (" << width << "x" << height << ")";
    EXPECT_EQ(found->seen_count(), board.point_count()) << seed;
  }
}

}  // namespace
}  // namespace arpipe::calib
