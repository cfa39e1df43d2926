// The tracker's search window (track.search_window): after a tracked frame the detector looks only
// around where the bundle is expected, and the whole frame when that finds fewer of the bundle's
// tags than should be in view. The poses must be the whole-frame search's, and a tag that jumps
// out of the window must still be found on the same frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
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

const fs::path kDefaultCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";

std::vector<FrameContext> track_all(const RecordingReader& reader, bool search_window) {
  Config config = test::tracking_config();
  config.track.search_window = search_window;
  return test::tracked_capture(reader, config);
}

// The whole default capture (a moving camera, a fast turn away, frames without the tag): the same
// state on every frame as the whole-frame search, and the same pose within a hundredth of the
// bounds against the truth in tag_tracker_test (1 mm, 0.5 degree). libapriltag works on the window
// as on the frame, but its corners come out of sums shifted by the window's corner, which differ
// in the last bits.
TEST(TagSearchWindow, GivesTheWholeFrameSearchsPosesOnTheDefaultCapture) {
  ASSERT_TRUE(fs::exists(kDefaultCapture / "recording.json")) << "the build simulates " << kDefaultCapture;
  const RecordingReader reader(kDefaultCapture);
  const auto windowed = track_all(reader, true);
  const auto whole = track_all(reader, false);
  int in_window = 0, tracked = 0;
  for (size_t i = 0; i < windowed.size(); ++i) {
    const PoseEstimate& a = windowed[i].pose;
    const PoseEstimate& b = whole[i].pose;
    ASSERT_EQ(a.state, b.state) << "frame " << i;
    EXPECT_FALSE(b.searched_window_only) << "frame " << i;
    if (a.state != TrackState::Tracking) continue;
    ++tracked;
    in_window += a.searched_window_only ? 1 : 0;
    EXPECT_EQ(a.tags_used, b.tags_used) << "frame " << i;
    EXPECT_LT(centre_mm(a.T_cam_world, b.T_cam_world), 0.01) << "frame " << i;
    EXPECT_LT(angle_deg(a.T_cam_world, b.T_cam_world), 0.005) << "frame " << i;
    // A frame after one without a measured pose has nowhere to look but everywhere.
    if (i == 0 || windowed[i - 1].pose.state != TrackState::Tracking) {
      EXPECT_FALSE(a.searched_window_only) << "frame " << i;
    }
  }
  // All tracked frames but the first of each tracked run were searched in the window alone.
  EXPECT_GE(tracked, 40);
  EXPECT_GE(in_window, tracked - 3);
}

// Frame `from` with its rows moved down by `rows` (up when negative; rows that come in are grey):
// the tag jumps in the image as no camera motion the prediction knows would move it.
Frame shifted(const Frame& from, int rows) {
  Frame frame = from;
  const size_t line = frame.bytes_per_line;
  for (int y = 0; y < frame.height; ++y) {
    uint8_t* row = frame.data.data() + size_t(y) * line;
    const int source = y - rows;
    if (source >= 0 && source < frame.height) {
      std::copy_n(from.data.data() + size_t(source) * line, line, row);
    } else {
      for (size_t x = 0; x + 1 < line; x += 2) row[x] = 128, row[x + 1] = 128;  // YUYV grey
    }
  }
  return frame;
}

TEST(TagSearchWindow, ATagThatJumpsOutOfTheWindowIsFoundInTheWholeFrameOnTheSameFrame) {
  ASSERT_TRUE(fs::exists(kDefaultCapture / "recording.json")) << "the build simulates " << kDefaultCapture;
  const RecordingReader reader(kDefaultCapture);
  ASSERT_EQ(reader.info().pixel_format, PixelFormat::YUYV);
  const auto camera = std::make_shared<CameraModel>(reader.camera_model());
  Config config = test::tracking_config();
  config.track.still_px = 0;  // frame 3 repeats frame 2, which a still camera would keep (tag_still_test)
  TagTracker tracker;
  tracker.configure(config);
  TagTracker whole_frame;
  config.track.search_window = false;
  whole_frame.configure(config);

  std::vector<FrameContext> frames(4);
  const auto track = [&](size_t i) {
    frames[i].camera_model = camera;
    frames[i].input_index = i;
    tracker.process(frames[i]);
    ASSERT_EQ(frames[i].pose.state, TrackState::Tracking) << "frame " << i;
  };
  for (size_t i = 0; i < 2; ++i) {
    reader.read(i, frames[i].camera);
    track(i);
  }
  // 180 rows towards the farther edge of the frame moves the tag (about 110 px across) wholly out of the
  // window around where frame 1 puts it (the tag plus 55 px each side), but keeps it in view.
  double centre_row = 0;
  for (const Vec2& corner : frames[1].pose.tags.at(0).corners) centre_row += corner[1] / 4;
  const int rows = centre_row < frames[1].camera.height / 2 ? 180 : -180;
  frames[2].camera = shifted(frames[1].camera, rows);
  frames[3].camera = frames[2].camera;
  for (size_t i = 2; i < 4; ++i) track(i);
  EXPECT_FALSE(frames[0].pose.searched_window_only);
  EXPECT_TRUE(frames[1].pose.searched_window_only);
  EXPECT_FALSE(frames[2].pose.searched_window_only) << "the jump must fall back to the whole frame";
  EXPECT_TRUE(frames[3].pose.searched_window_only) << "the window follows the tag to its new place";

  FrameContext reference;
  reference.camera = frames[2].camera;
  reference.camera_model = camera;
  whole_frame.process(reference);
  ASSERT_EQ(reference.pose.state, TrackState::Tracking);
  for (size_t i : {size_t(2), size_t(3)}) {
    EXPECT_LT(centre_mm(frames[i].pose.T_cam_world, reference.pose.T_cam_world), 0.01) << "frame " << i;
    EXPECT_LT(angle_deg(frames[i].pose.T_cam_world, reference.pose.T_cam_world), 0.005) << "frame " << i;
  }
  // The jump is real: the anchor lands about 180 rows away (the lens bends it a little).
  const auto before = camera->project(frames[1].pose.T_cam_world * Vec3{0, 0, 0});
  const auto after = camera->project(frames[2].pose.T_cam_world * Vec3{0, 0, 0});
  ASSERT_TRUE(before && after);
  EXPECT_GT(std::abs((*after)[1] - (*before)[1]), 160.0);
}

}  // namespace
}  // namespace arpipe
