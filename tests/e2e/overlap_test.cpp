// pipeline.overlap_first_stage: tracking frame n + 1 (and converting its camera picture for the
// composite stage) on a helper thread while the later stages render frame n must change nothing a
// replay shows: the same poses to the last bit and the same composited frames byte for byte, on
// the default capture (a moving camera, motion blur, the tag lost and found again), also with the
// motion stage holding each frame back for the next one. With nothing virtual nothing is tracked,
// and nothing runs ahead.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "kept_frames.h"

namespace arpipe {
namespace {

using namespace kept_frames;

TEST(OverlapFirstStage, AReplayIsTheSameFrameForFrame) {
  const std::vector<std::vector<std::string>> settings{{}, {"motion.latency_frames=1"}};
  for (const std::vector<std::string>& setting : settings) {
    const std::string what = setting.empty() ? "motion without latency" : setting.front();
    std::vector<std::string> apart = setting, overlapped = setting;
    apart.push_back("pipeline.overlap_first_stage=false");
    overlapped.push_back("pipeline.overlap_first_stage=true");
    PipelineMetrics apart_metrics, overlapped_metrics;
    const std::vector<Shown> a = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 60, apart, &apart_metrics);
    const std::vector<Shown> b =
        run(kConfigs / "arpipe.toml", kBuild / "default-capture", 60, overlapped, &overlapped_metrics);
    EXPECT_EQ(apart_metrics.frames_overlapped, 0u) << what;
    EXPECT_GT(overlapped_metrics.frames_overlapped, 30u) << what << ": a fast replay keeps the next frame waiting";
    ASSERT_EQ(a.size(), 60u) << what;
    ASSERT_EQ(b.size(), a.size()) << what;
    int tracked = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].index, b[i].index) << what;
      EXPECT_EQ(a[i].pose.state, b[i].pose.state) << what << ", frame " << i;
      EXPECT_EQ(a[i].pose.T_cam_world.rotation(), b[i].pose.T_cam_world.rotation()) << what << ", frame " << i;
      EXPECT_EQ(a[i].pose.T_cam_world.translation(), b[i].pose.T_cam_world.translation()) << what << ", frame " << i;
      EXPECT_TRUE(a[i].output.data == b[i].output.data) << what << ": frame " << i << " differs";
      tracked += a[i].pose.state == TrackState::Tracking;
    }
    EXPECT_GT(tracked, 40) << what;
  }
}

TEST(OverlapFirstStage, NothingRunsAheadWithNothingVirtual) {
  PipelineMetrics metrics;
  const std::vector<Shown> shown = run(kConfigs / "arpipe.toml", kBuild / "default-capture", 30,
                                       {"render.objects=[]", "pipeline.overlap_first_stage=true"}, &metrics);
  ASSERT_EQ(shown.size(), 30u);
  EXPECT_EQ(metrics.frames_overlapped, 0u);
  for (const Shown& frame : shown) EXPECT_FALSE(frame.output.data.empty()) << "frame " << frame.index;
}

}  // namespace
}  // namespace arpipe
