// AprilTag-grid detection against the simulator's truth: a 5 x 6 grid of tag36h11 tags (ids 3-32,
// one left unprinted) through the calib scene's wide OPENCV8 lens. Each seen tag's centre lies
// where the true centre projects; an unprinted tag and tags outside the image get weight -1; a view
// with too few tags, or a board file that does not match, gives no observation.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <set>

#include "calib/board_detector.h"
#include "tests/calib/calib_test_support.h"

namespace arpipe::calib {
namespace {

using namespace arpipe::calib::test;

constexpr int kRows = 5;
constexpr int kCols = 6;
constexpr double kTagSize = 0.03;
constexpr double kGap = 0.009;  // 0.3 x the tag: more than the 2 cells (7.5 mm) tag36h11 needs
constexpr double kPitch = kTagSize + kGap;
constexpr int kFirstId = 3;
constexpr int kUnprinted = 1 * kCols + 2;  // the tag at row 1, column 2 (id 11) is left out

CalibrationBoard grid_board() {
  CalibrationBoard board;
  board.name = "test-grid";
  board.kind = BoardKind::apriltag_grid;
  board.rows = kRows;
  board.cols = kCols;
  board.spacing_m = kPitch;
  board.family = "tag36h11";
  board.tag_size_m = kTagSize;
  board.first_id = kFirstId;
  return board;
}

// Centre of tag (row, col) in the world: the grid centred on the origin, row 0 at the top (+y), as
// the printed sheet lies on the table with its top edge away from -y.
Vec3 tag_centre(int row, int col) {
  return {(col - (kCols - 1) / 2.0) * kPitch, ((kRows - 1) / 2.0 - row) * kPitch, 0.0};
}

std::vector<Vec3> tag_centres() {
  std::vector<Vec3> out;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) out.push_back(tag_centre(r, c));
  return out;
}

// Frame 0: the whole grid, tilted; frame 1: looking straight down at the right of the grid, the
// left column outside the image and the next one cut by its edge; frame 2: the two right-hand
// columns inside, the next one cut.
std::string grid_scene() {
  std::string text = R"(description = "AprilTag grid 5 x 6 for calibration"
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
seed = 12
[trajectory]
kind = "keyframes"
[[trajectory.keyframe]]
time_s = 0.0
position = [0.07, -0.12, 0.36]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
roll_deg = 5
[[trajectory.keyframe]]
time_s = 0.5
position = [0.13, 0.0, 0.26]
look_at = [0.13, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
[[trajectory.keyframe]]
time_s = 1.0
position = [0.21, 0.0, 0.26]
look_at = [0.21, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
)";
  text += kTableLightAndSky;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) {
      const int index = r * kCols + c;
      if (index == kUnprinted) continue;
      const Vec3 p = tag_centre(r, c);
      text += fmt::format(
          "[[object]]\nname = \"tag{}\"\nposition = [{:.6f}, {:.6f}, 0.0]\n[object.texture]\nkind = \"apriltag\"\n"
          "family = \"tag36h11\"\nid = {}\nsize_m = {}\n",
          index, p[0], p[1], kFirstId + index, kTagSize);
    }
  return text;
}

// Rendered once for all the tests here, removed when they end.
struct GridCapture {
  fs::path recording;
  GridCapture() : recording(simulate_text(grid_scene(), scratch_dir("apriltag-grid"))) {}
  ~GridCapture() { remove_scratch(recording.parent_path()); }
};

const GridCapture& capture() {
  static const GridCapture instance;
  return instance;
}

std::optional<BoardObservation> detect(const BoardDetector& detector, const GreyImage& image) {
  return detector.detect(image.pixels.data(), image.width, image.height, static_cast<size_t>(image.width), image.name);
}

bool inside(const Vec2& p) { return p[0] >= 0 && p[1] >= 0 && p[0] <= 639 && p[1] <= 479; }

// Where the method without a lens puts a tag's centre when its corners are exact: the crossing of
// the diagonals of the true corners' images (independent of the detector's own code).
std::vector<Vec2> diagonal_centres(const RecordingReader& reader, size_t frame) {
  const double h = kTagSize / 2;
  std::vector<Vec2> out;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kCols; ++c) {
      const Vec3 m = tag_centre(r, c);
      const auto q = true_pixels(reader, frame, {m + Vec3{-h, -h, 0}, m + Vec3{h, -h, 0}, m + Vec3{h, h, 0}, m + Vec3{-h, h, 0}});
      // p = q0 + s (q2 - q0) = q1 + t (q3 - q1), solved by Cramer's rule.
      const double ax = q[2][0] - q[0][0], ay = q[2][1] - q[0][1], bx = q[1][0] - q[3][0], by = q[1][1] - q[3][1];
      const double rx = q[1][0] - q[0][0], ry = q[1][1] - q[0][1];
      const double s = (rx * by - ry * bx) / (ax * by - ay * bx);
      out.push_back({q[0][0] + s * ax, q[0][1] + s * ay});
    }
  return out;
}

// Bounds on a tag centre's error, 4 samples per pixel. Given the lens, the centre is where the lens
// puts it, up to the corners' own error: measured RMS 0.117 / 0.090 px, max 0.29 / 0.15 px in the
// full / partial view (0.02-0.04 px RMS at 16-64 samples: the render's coarse sampling of the edges
// is what costs). Without the lens the detector is held to what its method promises, the
// diagonals' crossing of the true corners' images, with the same corner error (measured RMS
// 0.115 / 0.180, max 0.29 / 0.28: the corners fitted with straight edges to the bent ones add a
// little). That point itself is off the true centre by the lens's bend over the tag (0.10 px RMS
// in the full view, 0.39 px near the image's edge with exact corners; measured here RMS 0.147 /
// 0.249, max 0.29 / 0.34), which the last, looser bound states: the reason for a second pass with
// the lens of a first solve.
constexpr double kCentreRmsPx = 0.2;
constexpr double kCentreMaxPx = 0.4;
constexpr double kLenslessMaxPx = 0.8;

TEST(AprilGridDetection, FullViewHasEveryPrintedTagAtItsCentre) {
  const RecordingReader reader(capture().recording);
  const auto images = images_from_recording(capture().recording);
  ASSERT_EQ(images->count(), 3u);
  const BoardDetector detector(grid_board());
  EXPECT_EQ(detector.method(), "apriltag");
  const GreyImage image = images->load(0);
  const auto start = std::chrono::steady_clock::now();
  const auto observation = detect(detector, image);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const auto with_lens = detector.detect(image.pixels.data(), image.width, image.height,
                                         static_cast<size_t>(image.width), image.name, reader.camera_model());
  ASSERT_TRUE(observation.has_value());
  ASSERT_TRUE(with_lens.has_value());
  EXPECT_EQ(observation->detector, "apriltag");
  ASSERT_EQ(observation->pixels.size(), static_cast<size_t>(kRows * kCols));
  const auto truth = true_pixels(reader, 0, tag_centres());
  for (int i = 0; i < kRows * kCols; ++i) {
    ASSERT_TRUE(inside(truth[static_cast<size_t>(i)])) << "the scene should show tag " << i;
    EXPECT_EQ(observation->weights[static_cast<size_t>(i)], i == kUnprinted ? -1.0 : 1.0) << "tag " << i;
    EXPECT_EQ(with_lens->weights[static_cast<size_t>(i)], i == kUnprinted ? -1.0 : 1.0) << "tag " << i;
  }
  const CornerErrors lensed = corner_errors(*with_lens, truth);
  EXPECT_EQ(lensed.seen, kRows * kCols - 1);
  EXPECT_LT(lensed.rms_px, kCentreRmsPx);
  EXPECT_LT(lensed.max_px, kCentreMaxPx);
  const CornerErrors method = corner_errors(*observation, diagonal_centres(reader, 0));
  EXPECT_LT(method.rms_px, kCentreRmsPx);
  EXPECT_LT(method.max_px, kCentreMaxPx);
  const CornerErrors lensless = corner_errors(*observation, truth);
  EXPECT_LT(lensless.max_px, kLenslessMaxPx);
  RecordProperty("rms_px_with_lens", fmt::format("{:.4f}", lensed.rms_px));
  RecordProperty("max_px_with_lens", fmt::format("{:.4f}", lensed.max_px));
  RecordProperty("rms_px_without_lens", fmt::format("{:.4f}", lensless.rms_px));
  RecordProperty("max_px_without_lens", fmt::format("{:.4f}", lensless.max_px));
  fmt::print("AprilTag grid, full view, {} tags: centre with lens RMS {:.4f} px, max {:.4f}; without: RMS {:.4f}, "
             "max {:.4f} (against the diagonals of the true corners: RMS {:.4f}, max {:.4f}); {:.1f} ms\n",
             lensed.seen, lensed.rms_px, lensed.max_px, lensless.rms_px, lensless.max_px, method.rms_px,
             method.max_px, ms);
}

TEST(AprilGridDetection, TagsOutsideTheImageGetWeightMinusOne) {
  const RecordingReader reader(capture().recording);
  const auto images = images_from_recording(capture().recording);
  const BoardDetector detector(grid_board());
  const GreyImage image = images->load(1);
  const auto observation = detect(detector, image);
  const auto with_lens = detector.detect(image.pixels.data(), image.width, image.height,
                                         static_cast<size_t>(image.width), image.name, reader.camera_model());
  ASSERT_TRUE(observation.has_value());
  ASSERT_TRUE(with_lens.has_value());
  const auto truth = true_pixels(reader, 1, tag_centres());
  int outside = 0;
  for (int i = 0; i < kRows * kCols; ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_EQ(with_lens->weights[k], observation->weights[k]) << "tag " << i;
    if (!inside(truth[k])) {
      ++outside;
      EXPECT_EQ(observation->weights[k], -1.0) << "tag " << i << " is outside the image";
    } else if (i == kUnprinted) {
      EXPECT_EQ(observation->weights[k], -1.0);
    } else if (truth[k][0] > 45) {  // black square and white ring inside (tags are ~46 px here)
      EXPECT_EQ(observation->weights[k], 1.0) << "tag " << i << " at x = " << truth[k][0];
    }
    if (observation->weights[k] <= 0) {
      EXPECT_EQ(observation->pixels[k], (Vec2{-1, -1}));
    }
  }
  EXPECT_GE(outside, kRows) << "the scene should put the left column outside the image";
  const CornerErrors lensed = corner_errors(*with_lens, truth);
  EXPECT_GE(lensed.seen, 18);  // 60 % of 30
  EXPECT_LT(lensed.rms_px, kCentreRmsPx);
  EXPECT_LT(lensed.max_px, kCentreMaxPx);
  const CornerErrors method = corner_errors(*observation, diagonal_centres(reader, 1));
  EXPECT_LT(method.rms_px, kCentreRmsPx);
  EXPECT_LT(method.max_px, kCentreMaxPx);
  const CornerErrors lensless = corner_errors(*observation, truth);
  EXPECT_LT(lensless.max_px, kLenslessMaxPx);
  fmt::print("AprilTag grid, partial view, {} of {} tags: centre with lens RMS {:.4f} px, max {:.4f}; without: RMS "
             "{:.4f}, max {:.4f} (against the diagonals of the true corners: RMS {:.4f}, max {:.4f})\n",
             lensed.seen, kRows * kCols, lensed.rms_px, lensed.max_px, lensless.rms_px, lensless.max_px,
             method.rms_px, method.max_px);
}

TEST(AprilGridDetection, UnknownFamilyIsABoardError) {
  CalibrationBoard board = grid_board();
  board.family = "tag99h99";
  EXPECT_THROW(BoardDetector{board}, BoardError);
}

TEST(AprilGridDetection, LensOfAnotherSizeGivesNothing) {
  const auto images = images_from_recording(capture().recording);
  const GreyImage image = images->load(0);
  const CameraModel other = CameraModel::pinhole(500, 500, 319.5, 239.5, 1280, 960);
  EXPECT_FALSE(BoardDetector(grid_board())
                   .detect(image.pixels.data(), image.width, image.height, static_cast<size_t>(image.width),
                           image.name, other)
                   .has_value());
}

TEST(AprilGridDetection, TooFewTagsGiveNothing) {
  const RecordingReader reader(capture().recording);
  const auto images = images_from_recording(capture().recording);
  const auto truth = true_pixels(reader, 2, tag_centres());
  int inside_count = 0;
  for (const Vec2& p : truth) inside_count += inside(p);
  ASSERT_LT(inside_count, 18) << "the scene should show fewer than 60 % of the tags";
  ASSERT_GE(inside_count, 4) << "the scene should still show some tags";
  EXPECT_FALSE(detect(BoardDetector(grid_board()), images->load(2)).has_value());
}

TEST(AprilGridDetection, WrongBoardGivesNothing) {
  const auto images = images_from_recording(capture().recording);
  const GreyImage image = images->load(0);
  // Ids 100 onwards are not in the scene; neither is any chessboard.
  CalibrationBoard other_ids = grid_board();
  other_ids.first_id = 100;
  EXPECT_FALSE(detect(BoardDetector(other_ids), image).has_value());
  CalibrationBoard other_family = grid_board();
  other_family.family = "tag25h9";
  EXPECT_FALSE(detect(BoardDetector(other_family), image).has_value());
  CalibrationBoard chess;
  chess.rows = 9;
  chess.cols = 13;
  chess.spacing_m = 0.02;
  EXPECT_FALSE(detect(BoardDetector(chess), image).has_value());
  // And the tag detector finds no grid in the chessboard capture.
  EXPECT_FALSE(detect(BoardDetector(grid_board()), images_from_recording(calib_capture())->load(0)).has_value());
}

}  // namespace
}  // namespace arpipe::calib
