// Chessboard detection against the simulator's truth: findChessboardCornersSB on every frame of the
// calib-board capture (a 9 x 13-corner board through a wide OPENCV8 lens), mrgingham on a rendered
// square board, and no observation where the board is absent or is not the board of the file.
//
// Measured while choosing the settings (calib-board capture, 60 frames, 7020 corners, noise on;
// per-point errors against the true projections; ms on the 2-core dev machine with other builds
// running, so only their ratios mean much):
//   findChessboardCornersSB flags      found  RMS px  max px  ms/frame
//   none                               60/60   0.121   1.54     149
//   NORMALIZE_IMAGE                    59/60   0.178   0.70     200
//   EXHAUSTIVE                         60/60   0.121   1.54     150
//   ACCURACY                           59/60   0.076   0.54     568
//   NORMALIZE | EXHAUSTIVE             59/60   0.178   0.70     131
//   NORMALIZE | ACCURACY               59/60   0.160   0.80     447
//   EXHAUSTIVE | ACCURACY              59/60   0.076   0.54     355
//   NORMALIZE | EXHAUSTIVE | ACCURACY  59/60   0.160   0.80     378
//   none + cornerSubPix, half window 0.4 x corner spacing in [2, 10] px
//                                      60/60   0.093   0.39   +1-2   <- chosen, with EXHAUSTIVE
//   the same with a fixed 3 px half window     0.103   0.39
//   the same with a fixed 5 px half window     0.175   4.31   (the window reaches the next corner)
//   findChessboardCorners + cornerSubPix       54/60   0.089   0.26
//   findChessboardCorners on a 2x upsampled image + cornerSubPix
//                                      60/60   0.094   0.29   3-5 where found, but 1-4.6 s to
//                                                             give up on a board of another size
// SB's worst corners are strongly sheared ones on oblique views; cornerSubPix removes them and any
// bias (mean error -0.002 px). The X-junction model fit after cornerSubPix (calib/
// chessboard_corner_fit.h; bench/calib_corners gives the table per coordinate): 0.027 px RMS, max
// 0.13 px on that 16-sample capture; the capture is now rendered with 36 samples per pixel, on
// which cornerSubPix alone gives 0.078 px (max 0.29) and with the fit 0.015 px (max 0.10), +0.2 s
// per image. mrgingham on 10 rendered views of its own board (16 samples/px):
// no preprocessing 8/10 found, 0.27 px RMS; its CLI's (stretch, CLAHE 8, 3x3 blur) 10/10, 0.136;
// that + cornerSubPix 0.051 (max 0.15), the same as SB + cornerSubPix on those views.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/board_detector.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

CalibrationBoard chessboard(int rows, int cols, double square_m = 0.02) {
  CalibrationBoard board;
  board.name = "test";
  board.kind = BoardKind::chessboard;
  board.rows = rows;
  board.cols = cols;
  board.spacing_m = square_m;
  return board;
}

std::optional<BoardObservation> detect(const BoardDetector& detector, const GreyImage& image) {
  return detector.detect(image.pixels.data(), image.width, image.height, static_cast<size_t>(image.width), image.name);
}

// Bounds for the chessboard detectors + cornerSubPix + the model fit on the calib-board capture.
// Measured (60 frames, 7020 corners, 36 samples per pixel, sensor noise on): RMS 0.015 px per point,
// worst corner 0.10 px, mean error 0.0000 px. Bounds with a margin for other views: 0.04 px RMS and
// 0.25 px for any corner (cornerSubPix alone gives 0.078 px RMS, so a fit that stopped working
// fails), and a mean error under 0.005 px: a bias shifts cx, cy one for one.
constexpr double kMaxRmsPx = 0.04;
constexpr double kMaxErrorPx = 0.25;
constexpr double kMaxBiasPx = 0.005;

struct FrameResult {
  std::optional<BoardObservation> observation;
  std::string name;
  double seconds = 0;
};

// Detects in every frame of a recording, on two threads (one detector each, as the API asks).
std::vector<FrameResult> detect_all(const CalibrationBoard& board, const CalibrationImages& images) {
  std::vector<FrameResult> results(images.count());
  const auto work = [&](size_t first) {
    const BoardDetector detector(board);
    for (size_t frame = first; frame < images.count(); frame += 2) {
      const GreyImage image = images.load(frame);
      const auto start = std::chrono::steady_clock::now();
      results[frame].observation = detect(detector, image);
      results[frame].seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      results[frame].name = image.name;
    }
  };
  std::thread other(work, 1);
  work(0);
  other.join();
  return results;
}

TEST(ChessboardDetection, FindsEveryCalibFrameWithinTolerance) {
  const RecordingReader reader(calib_capture());
  const auto images = images_from_recording(calib_capture());
  ASSERT_GE(images->count(), 20u);
  ASSERT_EQ(reader.ground_truth().size(), images->count());
  const CalibrationBoard board = chessboard(9, 13);
  EXPECT_EQ(BoardDetector(board).method(), "findChessboardCornersSB");
  const std::vector<FrameResult> results = detect_all(board, *images);
  ErrorTally tally;
  double sum_dx = 0, sum_dy = 0, seconds = 0;
  for (size_t frame = 0; frame < results.size(); ++frame) {
    const auto& observation = results[frame].observation;
    seconds += results[frame].seconds;
    ASSERT_TRUE(observation.has_value()) << "frame " << frame;
    EXPECT_EQ(observation->image, results[frame].name);
    EXPECT_EQ(observation->width, 640);
    EXPECT_EQ(observation->height, 480);
    EXPECT_EQ(observation->detector, "findChessboardCornersSB");
    ASSERT_EQ(observation->pixels.size(), 117u);
    EXPECT_EQ(observation->seen_count(), 117);
    for (double w : observation->weights) EXPECT_EQ(w, 1.0);

    const auto truth = in_detector_order(true_pixels(reader, frame, calib_capture_corners()), 13);
    const CornerErrors errors = corner_errors(*observation, truth);
    EXPECT_LT(errors.max_px, kMaxErrorPx) << "frame " << frame;
    tally.add(errors);
    for (size_t i = 0; i < truth.size(); ++i) {
      sum_dx += observation->pixels[i][0] - truth[i][0];
      sum_dy += observation->pixels[i][1] - truth[i][1];
    }
  }
  EXPECT_LT(tally.rms_px(), kMaxRmsPx);
  EXPECT_LT(std::abs(sum_dx / tally.points), kMaxBiasPx);
  EXPECT_LT(std::abs(sum_dy / tally.points), kMaxBiasPx);
  const double ms_per_frame = 1000 * seconds / static_cast<double>(results.size());
  RecordProperty("rms_px", fmt::format("{:.4f}", tally.rms_px()));
  RecordProperty("max_px", fmt::format("{:.4f}", tally.max_px));
  RecordProperty("ms_per_frame", fmt::format("{:.1f}", ms_per_frame));
  fmt::print("chessboard 9 x 13 on {} frames: RMS {:.4f} px, max {:.4f} px, mean error ({:.4f}, {:.4f}) px, "
             "{:.1f} ms/frame\n",
             results.size(), tally.rms_px(), tally.max_px, sum_dx / tally.points, sum_dy / tally.points,
             ms_per_frame);
}

// A board file that names the rows and columns the other way round describes the same board
// turned by 90 degrees in its own plane, which is right: the points must then be that turned grid
// (a proper rotation of the true corners, never a mirror image).
TEST(ChessboardDetection, TransposedBoardFileGivesTheTurnedGrid) {
  const RecordingReader reader(calib_capture());
  const auto images = images_from_recording(calib_capture());
  const BoardDetector detector(chessboard(13, 9));
  for (size_t frame : {size_t{0}, images->count() / 2}) {
    const auto observation = detect(detector, images->load(frame));
    ASSERT_TRUE(observation.has_value()) << "frame " << frame;
    const auto truth = true_pixels(reader, frame, calib_capture_corners());  // 9 rows (j) x 13 cols (i)
    // Point (r, c) of the 13 x 9 board is corner (i, j) = (r, 8 - c) or, turned, (12 - r, c).
    std::vector<Vec2> turned_a, turned_b;
    for (int r = 0; r < 13; ++r)
      for (int c = 0; c < 9; ++c) {
        turned_a.push_back(truth[static_cast<size_t>((8 - c) * 13 + r)]);
        turned_b.push_back(truth[static_cast<size_t>(c * 13 + (12 - r))]);
      }
    const double a = corner_errors(*observation, turned_a).max_px;
    const double b = corner_errors(*observation, turned_b).max_px;
    EXPECT_LT(std::min(a, b), kMaxErrorPx) << "frame " << frame << ": neither proper turn of the grid";
  }
}

TEST(ChessboardDetection, WrongCornerCountGivesNothing) {
  const auto images = images_from_recording(calib_capture());
  const GreyImage image = images->load(3);
  // A row fewer, a column more, and a square board (mrgingham, then SB).
  for (const auto& [rows, cols] : {std::pair{8, 13}, {9, 14}, {10, 10}}) {
    const BoardDetector detector(chessboard(rows, cols));
    EXPECT_FALSE(detect(detector, image).has_value()) << rows << " x " << cols << " by " << detector.method();
  }
}

TEST(ChessboardDetection, NoBoardGivesNothing) {
  const int width = 320, height = 240;
  std::vector<unsigned char> flat(static_cast<size_t>(width * height), 128);
  std::vector<unsigned char> noise(flat.size());
  std::mt19937 random(7);
  for (auto& v : noise) v = static_cast<unsigned char>(random() & 0xff);
  for (const auto& board : {chessboard(9, 13), chessboard(10, 10)}) {
    const BoardDetector detector(board);
    EXPECT_FALSE(detector.detect(flat.data(), width, height, width, "flat").has_value()) << detector.method();
    EXPECT_FALSE(detector.detect(noise.data(), width, height, width, "noise").has_value()) << detector.method();
    EXPECT_FALSE(detector.detect(nullptr, width, height, width, "null").has_value());
    EXPECT_FALSE(detector.detect(flat.data(), 4, 4, 4, "tiny").has_value());
    EXPECT_FALSE(detector.detect(flat.data(), width, height, width - 1, "bad stride").has_value());
  }
}

// mrgingham's board (chessboard.10x10.pdf, as configs/boards/chessboard-10x10-mrgingham.toml
// prints it): 11 x 11 squares of 15 mm, the outer ring twice as wide, one square of paper around,
// 225 mm in all, drawn 20 texels to the square. Texel edges fall on square edges, so the inner
// corners are exactly at x = (-4.5 + i) 15 mm, y = (4.5 - j) 15 mm (row j from the top).
constexpr double kSquare = 0.015;
constexpr int kTexelsPerSquare = 20;

void write_mrgingham_board(const fs::path& png) {
  const std::vector<int> edges{1, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 14};  // in squares, from the left/top
  cv::Mat image(15 * kTexelsPerSquare, 15 * kTexelsPerSquare, CV_8UC1, cv::Scalar(235));
  for (int a = 0; a < 11; ++a)
    for (int b = 0; b < 11; ++b)
      if ((a + b) % 2 == 0)
        image(cv::Range(edges[a] * kTexelsPerSquare, edges[a + 1] * kTexelsPerSquare),
              cv::Range(edges[b] * kTexelsPerSquare, edges[b + 1] * kTexelsPerSquare)) = 20;
  ASSERT_TRUE(cv::imwrite(png.string(), image));
}

// The board through the calib scene's lens from three places, the image rolled by 0, -10 and 15
// degrees (mrgingham wants the board's edges roughly along the image's).
std::string mrgingham_scene() {
  return R"(description = "mrgingham's 10 x 10 board"
[camera]
lensmodel = "LENSMODEL_OPENCV8"
intrinsics = [520.0, 521.5, 323.0, 237.0, -0.28, 0.11, 0.0005, -0.0004, -0.02, 0.04, 0.01, 0.0]
width = 640
height = 480
pixel_format = "YUYV"
fps = 2
exposure_ms = 0.2
[camera.sensor]
sensitivity = 2000.0
[render]
samples_per_pixel = 4
frames = 3
seed = 11
[trajectory]
kind = "keyframes"
[[trajectory.keyframe]]
time_s = 0.0
position = [0.0, -0.05, 0.45]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
[[trajectory.keyframe]]
time_s = 0.5
position = [0.15, 0.1, 0.40]
look_at = [0.02, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
roll_deg = -10
[[trajectory.keyframe]]
time_s = 1.0
position = [-0.25, 0.2, 0.4]
look_at = [-0.05, 0.05, 0.0]
up = [0.0, 1.0, 0.0]
roll_deg = 15
[[object]]
name = "table"
position = [0.0, 0.0, -0.0005]
width_m = 2.0
height_m = 2.0
albedo = [0.35, 0.30, 0.25]
[[object]]
name = "board"
width_m = 0.225
height_m = 0.225
[object.texture]
kind = "image"
image = "board.png"
[[light]]
direction = [0.3, -0.4, 1.0]
irradiance = 4.0
[environment]
radiance = [0.30, 0.30, 0.33]
)";
}

// Bounds for mrgingham + cornerSubPix + the model fit on this 4-samples-per-pixel render: measured
// on these 3 views RMS 0.035 px, max 0.12 px (cornerSubPix alone, on 10 views: 0.11 / 0.30; the
// coarse sampling of the edges is what costs), so 0.07 px RMS and 0.3 px for any corner.
constexpr double kMrginghamMaxRmsPx = 0.07;
constexpr double kMrginghamMaxErrorPx = 0.3;

TEST(ChessboardDetection, MrginghamFindsItsOwnBoard) {
  const fs::path dir = scratch_dir("mrgingham");
  write_mrgingham_board(dir / "board.png");
  const fs::path recording = simulate_text(mrgingham_scene(), dir);
  const RecordingReader reader(recording);
  const auto images = images_from_recording(recording);
  ASSERT_EQ(images->count(), 3u);
  const BoardDetector detector(chessboard(10, 10, kSquare));
  EXPECT_EQ(detector.method(), "mrgingham");
  std::vector<Vec3> corners;
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) corners.push_back({(-4.5 + i) * kSquare, (4.5 - j) * kSquare, 0.0});
  ErrorTally tally;
  double seconds = 0;
  for (size_t frame = 0; frame < images->count(); ++frame) {
    const GreyImage image = images->load(frame);
    const auto start = std::chrono::steady_clock::now();
    const auto observation = detect(detector, image);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(observation.has_value()) << "frame " << frame;
    EXPECT_EQ(observation->detector, "mrgingham") << "frame " << frame;
    ASSERT_EQ(observation->seen_count(), 100);
    // Weights are 2^-level; a sharp board is refined at full resolution (level 0) nearly everywhere.
    int full_resolution = 0;
    for (double w : observation->weights) {
      EXPECT_TRUE(w == 1 || w == 0.5 || w == 0.25 || w == 0.125) << w;
      full_resolution += w == 1;
    }
    EXPECT_GE(full_resolution, 90) << "frame " << frame;
    // With rolls of at most 15 degrees, the order is the truth's own (rows left to right).
    const CornerErrors errors = corner_errors(*observation, true_pixels(reader, frame, corners));
    EXPECT_LT(errors.max_px, kMrginghamMaxErrorPx) << "frame " << frame;
    tally.add(errors);
  }
  EXPECT_LT(tally.rms_px(), kMrginghamMaxRmsPx);
  RecordProperty("rms_px", fmt::format("{:.4f}", tally.rms_px()));
  RecordProperty("max_px", fmt::format("{:.4f}", tally.max_px));
  fmt::print("mrgingham + cornerSubPix + model fit on {} frames (4 samples/px): RMS {:.4f} px, max {:.4f} px, {:.1f} ms/frame\n",
             images->count(), tally.rms_px(), tally.max_px, 1000 * seconds / static_cast<double>(images->count()));
  remove_scratch(dir);
}

}  // namespace
}  // namespace arpipe::calib
