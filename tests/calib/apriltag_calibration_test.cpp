// The whole calibration with an AprilTag grid (configs/boards/aprilgrid-6x8-tag36h11.toml) through
// the calib scene's wide OPENCV8 lens: the first 30 keyframes of configs/sim/calib-board.toml with
// the grid in place of the chessboard, 9 samples per pixel. The second pass, which places each tag's
// centre through the first solve's lens, must place the centres where the true lens would.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "calib/board_detection_set.h"
#include "calib/calibration_run.h"
#include "calib/projection_uncertainty.h"
#include "core/config/text_file.h"
#include "tests/calib/calib_test_support.h"
#include "tests/calib/solver_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

const fs::path kSourceDir = ARPIPE_SOURCE_DIR;

// calib-board.toml up to its objects, fewer frames and samples, then the table and the 48 tags
// (id = row * 8 + col, row 0 along +y, the grid centred on the origin).
std::string grid_scene(const CalibrationBoard& board) {
  std::string why;
  std::string text = read_text_file(kSourceDir / "configs/sim/calib-board.toml", why).value_or("");
  EXPECT_TRUE(why.empty()) << why;
  text = text.substr(0, text.find("[[object]]"));
  const auto set = [&text](const std::string& key, const std::string& value) {
    const size_t at = text.find("\n" + key + " = ");
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at + 1, text.find('\n', at + 1) - at - 1, key + " = " + value);
  };
  set("samples_per_pixel", "9");
  set("frames", "30");
  text += kTableLightAndSky;
  const double pitch = board.spacing_m;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c)
      text += fmt::format(
          "[[object]]\nname = \"tag{}\"\nposition = [{:.6f}, {:.6f}, 0.0]\n[object.texture]\nkind = \"apriltag\"\n"
          "family = \"{}\"\nid = {}\nsize_m = {}\n",
          r * board.cols + c, (c - (board.cols - 1) / 2.0) * pitch, ((board.rows - 1) / 2.0 - r) * pitch,
          board.family, board.first_id + r * board.cols + c, board.tag_size_m);
  return text;
}

// Where each tag's centre truly projects, for every view of a detection set.
ErrorTally centre_errors(const DetectionSet& set, const RecordingReader& reader, const CalibrationBoard& board) {
  std::vector<Vec3> world;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c)
      world.push_back({(c - (board.cols - 1) / 2.0) * board.spacing_m, ((board.rows - 1) / 2.0 - r) * board.spacing_m, 0});
  ErrorTally tally;
  for (const BoardObservation& view : set.views) {
    const size_t frame = std::stoul(view.image.substr(view.image.rfind(' ') + 1));  // "<dir> frame <n>"
    tally.add(corner_errors(view, true_pixels(reader, frame, world)));
  }
  return tally;
}

// Measured (the grid found in 26 of the 30 views, 1178 tag centres): centres off by 0.1216 px RMS without the lens, 0.1187 px
// through the first solve's lens, 0.1186 px through the true lens. The lens's bias is removed
// (0.027 px RMS of it), but at this render's 0.12 px of other centre noise (9 samples per pixel;
// a chessboard's corners carry 0.011 px) the solved lens is set by the noise, not by the bias, so
// what is asserted about the lens is that it lies within its reported uncertainty.
TEST(AprilTagCalibration, SecondPassPlacesTheCentresThroughTheLens) {
  const CalibrationBoard board = load_board(kSourceDir / "configs/boards/aprilgrid-6x8-tag36h11.toml");
  const fs::path dir = scratch_dir("apriltag-calibration");
  const fs::path recording = simulate_text(grid_scene(board), dir);
  const RecordingReader reader(recording);
  const auto images = images_from_recording(recording);
  const CameraModel truth = reader.camera_model();
  SolveOptions options;  // OPENCV8, the default

  // The first pass by hand, as run_calibration does it; then the whole run.
  const DetectionSet first_found = detect_boards(*images, board, 2);
  const CalibrationResult first = solve_calibration(board, first_found.views, 640, 480, options);
  const CalibrationRun run = run_calibration(*images, board, options, 2);
  ASSERT_TRUE(run.first_pass_rms_per_point_px.has_value());
  EXPECT_DOUBLE_EQ(*run.first_pass_rms_per_point_px, first.rms_per_point_px);
  EXPECT_EQ(run.found.views.size(), first_found.views.size());
  EXPECT_GE(run.found.views.size(), 25u);

  // The centres: closer to the truth than without the lens, and as close as the true lens puts
  // them (within 0.003 px RMS: the first solve's lens is off by tenths of a pixel, which moves a
  // centre by a second-order amount).
  const double without_lens = centre_errors(first_found, reader, board).rms_px();
  const double with_solved_lens = centre_errors(run.found, reader, board).rms_px();
  const double with_true_lens = centre_errors(detect_boards(*images, board, 2, {}, &truth), reader, board).rms_px();
  std::printf("AprilTag grid, %zu views: tag centres %.4f px RMS without the lens, %.4f through the first solve's, "
              "%.4f through the true one\n",
              run.found.views.size(), without_lens, with_solved_lens, with_true_lens);
  EXPECT_LT(with_solved_lens, without_lens);
  EXPECT_NEAR(with_solved_lens, with_true_lens, 0.003);

  // The lens: fx, fy within the 0.5 %, and the projection difference from the true lens
  // within 3 sigma of the uncertainty the solve reports at the image's centre and corners.
  const CameraModel& solved = run.result.model;
  EXPECT_NEAR(solved.fx() / truth.fx(), 1.0, 0.005);
  EXPECT_NEAR(solved.fy() / truth.fy(), 1.0, 0.005);
  const auto everywhere = [](const Vec2&) { return true; };
  const Mat3 R = implied_rotation(truth, solved, 16, everywhere);
  const std::vector<Vec2> points{{319.5, 239.5}, {0, 0}, {639, 0}, {0, 479}, {639, 479}};
  const auto sigma = projection_uncertainty(run.result, points, 0.0);
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec2 q = points[i];
    const Vec2 moved = *solved.project(mat_mul(R, *truth.unproject(q)));
    EXPECT_LT(std::hypot(moved[0] - q[0], moved[1] - q[1]), 3 * sigma[i].worst_direction_stdev_px)
        << "at " << q[0] << ", " << q[1];
  }
  remove_scratch(dir);
}

}  // namespace
}  // namespace arpipe::calib
