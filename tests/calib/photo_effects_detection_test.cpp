// Issue 25's bar on a simulated capture with real-photo effects: configs/sim/calib-board-photo.toml
// (JPEG quality 75, 1.25 px of defocus, vignetting leaving 55 % of the light in the corners, a
// lamp's uneven light and its highlight on a glossy board in frames 15 and 16). On its first 20
// frames, no view is lost that OpenCV's classic or SB finder (default flags, called here directly)
// finds, and the corners stay within a stated error of the truth.
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "calib/board_detector.h"
#include "calib/calibration_board.h"
#include "calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

TEST(PhotoEffectsDetection, NoViewLostThatOpenCVFindsAndCornersNearTheTruth) {
  std::ifstream in(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "calib-board-photo.toml");
  std::stringstream text;
  text << in.rdbuf();
  const fs::path dir = scratch_dir("photo-effects");
  sim::SimScene scene = sim::parse_sim_scene(text.str(), (dir / "scene.toml").string(), dir);
  // 9 samples a pixel instead of the scene's 36 keep the test to 15 s; the board's edges alias a
  // little more, which only makes finding and placing the corners harder.
  scene.render.samples_per_pixel = 9;
  sim::SimulateOptions options;
  options.out_dir = dir / "recording";
  options.threads = 2;
  options.frames = 20;
  sim::simulate(scene, options);

  const RecordingReader reader(options.out_dir);
  const auto images = images_from_recording(options.out_dir);
  const CalibrationBoard board = load_board(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "boards" / "chessboard-10x14-20mm.toml");
  const BoardDetector detector(board);
  int standard = 0, found = 0;
  ErrorTally tally;
  for (size_t f = 0; f < images->count(); ++f) {
    const GreyImage image = images->load(f);
    const cv::Mat grey(image.height, image.width, CV_8UC1, const_cast<unsigned char*>(image.pixels.data()));
    std::vector<cv::Point2f> corners;
    const bool classic = cv::findChessboardCorners(grey, cv::Size(board.cols, board.rows), corners);
    const bool sb = cv::findChessboardCornersSB(grey, cv::Size(board.cols, board.rows), corners);
    const auto observation = detector.detect(image.pixels.data(), image.width, image.height, size_t(image.width), image.name);
    standard += classic || sb;
    if (classic || sb) {
      EXPECT_TRUE(observation.has_value()) << "frame " << f << " (classic " << classic << ", SB " << sb << ")";
    }
    if (!observation) continue;
    ++found;
    const auto truth = in_detector_order(true_pixels(reader, f, calib_capture_corners()), board.cols);
    tally.add(corner_errors(*observation, truth));
  }
  EXPECT_GE(standard, 18);  // measured when written: SB finds all 20, the classic finder 19
  EXPECT_EQ(found, 20);
  // The model fit's corners on the full capture (36 samples): 0.024 px per coordinate, 0.034 px
  // per point, largest 0.13 px (docs/BENCHMARKS.md); here (9 samples, measured when written)
  // 0.047 px per point, largest 0.15 px. The bars: cornerSubPix alone on the full capture (0.062 px
  // per coordinate, 0.088 px per point; largest 0.40 px), so a model fit that stopped working on
  // these images fails the test.
  EXPECT_LT(tally.rms_px(), 0.088);
  EXPECT_LT(tally.max_px, 0.40);
  std::printf("photo effects, %d frames: found %d (OpenCV %d); corners RMS %.4f px per point, largest %.3f px\n",
              int(images->count()), found, standard, tally.rms_px(), tally.max_px);

  // The classic finder alone, last in the cascade: under the lamp's glare it puts some corners on
  // the wrong junction, where no refinement moves them (without the grid check, measured: one
  // corner 9.1 px off here, up to 9.8 px on the full capture); the check drops it (here that one
  // corner of 1989), so every corner it keeps is near the truth (largest 0.149 px here).
  const BoardDetector classic_only(board, CornerRefinement::model_fit, {ChessboardFinder::classic});
  ErrorTally classic_tally;
  int classic_dropped = 0;
  for (size_t f = 0; f < images->count(); ++f) {
    const GreyImage image = images->load(f);
    const auto observation = classic_only.detect(image.pixels.data(), image.width, image.height, size_t(image.width), image.name);
    if (!observation) continue;
    classic_dropped += observation->refined.dropped;
    classic_tally.add(corner_errors(*observation, in_detector_order(true_pixels(reader, f, calib_capture_corners()), board.cols)));
  }
  std::printf("classic finder alone: %d corners, %d dropped; RMS %.4f px per point, largest %.3f px\n",
              classic_tally.points, classic_dropped, classic_tally.rms_px(), classic_tally.max_px);
  EXPECT_LT(classic_tally.max_px, 0.40);
  remove_scratch(dir);
}

}  // namespace
}  // namespace arpipe::calib
