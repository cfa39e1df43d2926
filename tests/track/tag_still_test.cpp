// A still camera (track.still_px): while the tags' patch has not moved since the last detection,
// the tracker keeps that detection's pose instead of detecting again. On the still capture every
// frame after the first keeps it, within the truth's bounds; a moving camera never does; anything
// crossing the tags ends it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "core/track/tag_tracker.h"
#include "tests/track/simulated_capture.h"
#include "tests/track/tracked_capture.h"
#include "tests/track/tracking_config.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;
using test::angle_deg;
using test::centre_mm;

const fs::path kStillCapture = fs::path(ARPIPE_BINARY_DIR) / "tag-static-capture";
const fs::path kDefaultCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";

std::vector<FrameContext> track_all(const RecordingReader& reader, double still_px, size_t frames = 0) {
  Config config = test::tracking_config();
  config.track.still_px = still_px;
  return test::tracked_capture(reader, config, frames);
}

// The still capture: 10 frames of one pose, fresh sensor noise in each, looped three times.
TEST(TagStill, AStillCameraKeepsTheFirstDetectionsPose) {
  ASSERT_TRUE(fs::exists(kStillCapture / "recording.json")) << "the build simulates " << kStillCapture;
  const RecordingReader reader(kStillCapture);
  const SE3& truth = reader.ground_truth().at(0).T_cam_world_mid;
  const auto frames = track_all(reader, 0.05, 3 * reader.frame_count());
  ASSERT_EQ(frames[0].pose.state, TrackState::Tracking);
  EXPECT_FALSE(frames[0].pose.image_still);
  for (size_t i = 1; i < frames.size(); ++i) {
    const PoseEstimate& pose = frames[i].pose;
    ASSERT_EQ(pose.state, TrackState::Tracking) << "frame " << i;
    EXPECT_TRUE(pose.image_still) << "frame " << i;
    EXPECT_FALSE(pose.searched_window_only) << "frame " << i;
    // The very pose of the detection it kept, bit for bit, and its tags.
    EXPECT_EQ(pose.T_cam_world.translation(), frames[0].pose.T_cam_world.translation()) << "frame " << i;
    ASSERT_EQ(pose.tags.size(), frames[0].pose.tags.size());
  }
  // Within tag_tracker_test's bounds against the truth (1 mm, 0.5 degree).
  EXPECT_LT(centre_mm(frames[0].pose.T_cam_world, truth), 1.0);
  EXPECT_LT(angle_deg(frames[0].pose.T_cam_world, truth), 0.5);
  // Off: every frame detected.
  for (const FrameContext& ctx : track_all(reader, 0.0)) EXPECT_FALSE(ctx.pose.image_still);
}

// The default capture moves all the time (0.3-3 px a frame): no frame may keep a pose, and every
// frame's state and pose are the detector's.
TEST(TagStill, AMovingCameraDetectsEveryFrame) {
  ASSERT_TRUE(fs::exists(kDefaultCapture / "recording.json")) << "the build simulates " << kDefaultCapture;
  const RecordingReader reader(kDefaultCapture);
  const auto with = track_all(reader, 0.05);
  const auto without = track_all(reader, 0.0);
  for (size_t i = 0; i < with.size(); ++i) {
    EXPECT_FALSE(with[i].pose.image_still) << "frame " << i;
    ASSERT_EQ(with[i].pose.state, without[i].pose.state) << "frame " << i;
    if (with[i].pose.state == TrackState::Tracking) {
      EXPECT_EQ(with[i].pose.T_cam_world.translation(), without[i].pose.T_cam_world.translation()) << "frame " << i;
    }
  }
}

// Something over part of the tag (a finger: a dark block over a fifth of its width) is not
// stillness, though the rest of the patch stands still; nor is a jump of a tenth of a pixel.
TEST(TagStill, AnOccluderOrASmallMotionEndsIt) {
  ASSERT_TRUE(fs::exists(kStillCapture / "recording.json")) << "the build simulates " << kStillCapture;
  const RecordingReader reader(kStillCapture);
  const auto camera = std::make_shared<CameraModel>(reader.camera_model());
  Config config = test::tracking_config();
  TagTracker tracker;
  tracker.configure(config);
  std::vector<FrameContext> frames(3);
  for (size_t i = 0; i < frames.size(); ++i) {
    reader.read(i, frames[i].camera);
    frames[i].camera_model = camera;
    frames[i].input_index = i;
  }
  tracker.process(frames[0]);
  ASSERT_EQ(frames[0].pose.state, TrackState::Tracking);
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const Vec2& c : frames[0].pose.tags.at(0).corners)
    x0 = std::min(x0, c[0]), y0 = std::min(y0, c[1]), x1 = std::max(x1, c[0]), y1 = std::max(y1, c[1]);
  Frame& covered = frames[1].camera;  // YUYV: luma at even bytes
  const int bx = int(x0 + 0.4 * (x1 - x0)), by = int(y0 + 0.4 * (y1 - y0)), side = int(0.2 * (x1 - x0));
  for (int y = by; y < by + side; ++y)
    for (int x = bx; x < bx + side; ++x) covered.data[size_t(y) * covered.bytes_per_line + 2 * size_t(x)] = 16;
  tracker.process(frames[1]);
  EXPECT_FALSE(frames[1].pose.image_still);

  // A fresh tracker: frame 0, then frame 2 moved right by 0.1 px (each row resampled linearly).
  TagTracker fresh;
  fresh.configure(config);
  FrameContext first;
  reader.read(0, first.camera);
  first.camera_model = camera;
  fresh.process(first);
  Frame& moved = frames[2].camera;
  const Frame original = moved;
  for (int y = 0; y < moved.height; ++y)
    for (int x = 1; x < moved.width; ++x) {
      const uint8_t* row = original.data.data() + size_t(y) * original.bytes_per_line;
      moved.data[size_t(y) * moved.bytes_per_line + 2 * size_t(x)] =
          uint8_t(std::lround(0.9 * row[2 * x] + 0.1 * row[2 * (x - 1)]));
    }
  fresh.process(frames[2]);
  ASSERT_EQ(frames[2].pose.state, TrackState::Tracking);
  EXPECT_FALSE(frames[2].pose.image_still);
}

TEST(TagStill, OutOfRangeIsAConfigErrorNamingTheKey) {
  EXPECT_THROW(parse_config("[track]\nstill_px = 2\n", "still.toml"), ConfigError);
  try {
    parse_config("[track]\nstill_px = -0.1\n", "still.toml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("track.still_px"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("still.toml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arpipe
