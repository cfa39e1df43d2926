// A corner off its neighbours' homography (calib/grid_consistency.h): none on the true corners of
// the calib-board capture through its wide lens, and displaced ones found wherever they are.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "calib/grid_consistency.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

constexpr int kRows = 9, kCols = 13;

// The true corners bend with the lens (115 px at the image corners) but never off the homography
// of their neighbours by more than a small share of a square: measured at most 0.021 over the 60
// frames (every corner of every view, the board's edges and corners included), a fifth of the
// threshold.
TEST(GridConsistency, TrueCornersThroughTheWideLensAreOnTheGrid) {
  const RecordingReader reader(calib_capture());
  double worst = 0;
  for (size_t frame = 0; frame < reader.frame_count(); ++frame) {
    const std::vector<Vec2> truth = true_pixels(reader, frame, calib_capture_corners());
    std::vector<double> weights(truth.size(), 1.0);
    worst = std::max(worst, farthest_off_grid(kRows, kCols, truth, weights).share);
    EXPECT_EQ(drop_off_grid_corners(kRows, kCols, truth, weights), 0) << "frame " << frame;
  }
  std::printf("true corners: at most %.4f of a square off their neighbours' homography\n", worst);
  EXPECT_LT(worst, kMaxOffGridShare / 4);
}

// Corners moved by a fifth to a half of a square, inside the board, on its edge, at its corner and
// two side by side: each is dropped, and nothing else.
TEST(GridConsistency, DisplacedCornersAreDroppedAndOnlyThey) {
  const RecordingReader reader(calib_capture());
  for (const size_t frame : {size_t(0), size_t(29), size_t(59)}) {
    std::vector<Vec2> pixels = true_pixels(reader, frame, calib_capture_corners());
    const double square = std::hypot(pixels[1][0] - pixels[0][0], pixels[1][1] - pixels[0][1]);
    struct Move {
      int index;
      double dx, dy;  // in squares
    };
    const Move moves[] = {{4 * kCols + 6, 0.3, 0.0},     // inside
                          {0, -0.2, 0.2},                // the board's corner
                          {kCols * 8 + 5, 0.0, 0.25},    // the bottom edge
                          {2 * kCols + 10, 0.5, 0.5},    // two side by side
                          {2 * kCols + 11, 0.25, -0.25}};
    for (const Move& m : moves) {
      pixels[size_t(m.index)][0] += m.dx * square;
      pixels[size_t(m.index)][1] += m.dy * square;
    }
    std::vector<double> weights(pixels.size(), 1.0);
    EXPECT_EQ(drop_off_grid_corners(kRows, kCols, pixels, weights), 5) << "frame " << frame;
    for (const Move& m : moves) EXPECT_LT(weights[size_t(m.index)], 0) << "frame " << frame << " corner " << m.index;
  }
}

// A board seen in part (weights 0 or -1 for the missing corners) is judged by what remains; a
// corner with fewer than 6 seen neighbours within two squares is not judged.
TEST(GridConsistency, MissingCornersAreLeftOutOfTheJudgement) {
  const RecordingReader reader(calib_capture());
  std::vector<Vec2> pixels = true_pixels(reader, 10, calib_capture_corners());
  std::vector<double> weights(pixels.size(), 1.0);
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < 6; ++c) weights[size_t(r * kCols + c)] = -1.0;  // the left half unseen
  pixels[size_t(4 * kCols + 9)][0] += 5.0;
  EXPECT_EQ(drop_off_grid_corners(kRows, kCols, pixels, weights), 1);
  EXPECT_LT(weights[size_t(4 * kCols + 9)], 0);
  std::vector<double> lonely(pixels.size(), -1.0);
  lonely[0] = lonely[1] = lonely[kCols] = 1.0;  // three corners: nothing to judge by
  EXPECT_EQ(farthest_off_grid(kRows, kCols, pixels, lonely).index, -1);
}

// Pixels no homography fits (every corner at one place, or all on one line): nothing is judged,
// nothing thrown (the detector never throws).
TEST(GridConsistency, DegenerateGridsAreNotJudged) {
  std::vector<Vec2> same(size_t(kRows * kCols), Vec2{100, 100});
  std::vector<double> weights(same.size(), 1.0);
  EXPECT_NO_THROW(drop_off_grid_corners(kRows, kCols, same, weights));
  std::vector<Vec2> line;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) line.push_back({10.0 * (r * kCols + c), 50});
  std::vector<double> line_weights(line.size(), 1.0);
  EXPECT_NO_THROW(drop_off_grid_corners(kRows, kCols, line, line_weights));
}

}  // namespace
}  // namespace arpipe::calib
