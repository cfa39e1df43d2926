// The head-pose track: its angles and quaternions against the view's stated convention, slerp
// between samples against the analytic turn, and hostile files refused naming the file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "capture/panorama/head_pose_track.h"
#include "capture/panorama/panorama_source.h"
#include "capture/panorama/panorama_view.h"
#include "core/scene/asset_error.h"
#include "tests/capture/capture_test_support.h"

namespace arpipe {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180;

void expect_same(const Mat3& a, const Mat3& b, double tolerance, const std::string& what) {
  for (size_t r = 0; r < 3; ++r)
    for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(a[r][c], b[r][c], tolerance) << what << " [" << r << "][" << c << "]";
}

TEST(HeadPoseTrack, RollTiltsTheViewsRightSideDown) {
  // Yaw 0, pitch 0, roll 30: the camera's right axis (column 0) dips below the horizon by 30
  // degrees (panorama y is up), its forward axis stays on the image's centre.
  const Mat3 R = panorama_view_rotation(0, 0, 30 * kDeg);
  EXPECT_NEAR(R[0][0], std::cos(30 * kDeg), 1e-15);
  EXPECT_NEAR(R[1][0], -std::sin(30 * kDeg), 1e-15);
  EXPECT_NEAR(R[2][2], -1, 1e-15);
  expect_same(panorama_view_rotation(0.4, -0.3, 0), panorama_view_rotation(0.4, -0.3), 0, "roll 0");
}

TEST(HeadPoseTrack, AnglesAndQuaternionsMeanTheSameTurns) {
  // OpenXR's head frame (x right, y up, -z forward): the identity looks at the centre; a turn of
  // -90 degrees about y looks right (yaw 90); +90 about x looks up (pitch 90); -30 about z (forward
  // is -z) tilts the right side down (roll 30).
  const double h = std::sqrt(0.5);
  const HeadPoseTrack q = HeadPoseTrack::parse(
      "# a recorded head track\n"
      "t_s, qw, qx, qy, qz\n"
      "0, 1, 0, 0, 0\n"
      "1, " + std::to_string(h) + ", 0, " + std::to_string(-h) + ", 0\n"
      "2, " + std::to_string(h) + ", " + std::to_string(h) + ", 0, 0\n"
      "3, " + std::to_string(std::cos(15 * kDeg)) + ", 0, 0, " + std::to_string(-std::sin(15 * kDeg)) + "\n",
      "quaternions");
  ASSERT_EQ(q.samples().size(), 4u);
  expect_same(q.rotation_at(0), panorama_view_rotation(0, 0), 1e-6, "identity");
  expect_same(q.rotation_at(1), panorama_view_rotation(90 * kDeg, 0), 1e-6, "yaw 90");
  expect_same(q.rotation_at(2), panorama_view_rotation(0, 90 * kDeg), 1e-6, "pitch 90");
  expect_same(q.rotation_at(3), panorama_view_rotation(0, 0, 30 * kDeg), 1e-6, "roll 30");
}

TEST(HeadPoseTrack, TurnsAtConstantRateBetweenSamplesAndHoldsOutside) {
  // Columns in another order, an extra column, CRLF and tabs. Level, yaw 0 -> 90 over 2 s is yaw 45
  // at 1 s and 22.5 at 0.5 s (slerp about the vertical); before the first and after the last
  // sample the end orientations hold.
  const HeadPoseTrack track =
      HeadPoseTrack::parse("frame\tpitch_deg\tyaw_deg\tt_s\r\n7\t10\t0\t1.0\r\n8\t10\t90\t3.0\r\n", "reordered");
  expect_same(track.rotation_at(1.0), panorama_view_rotation(0, 10 * kDeg), 1e-15, "the first sample");
  expect_same(track.rotation_at(3.0), panorama_view_rotation(90 * kDeg, 10 * kDeg), 1e-15, "the second sample");
  // Slerp and "yaw then pitch" agree exactly only at pitch 0: there, to rounding.
  const HeadPoseTrack level = HeadPoseTrack::parse("t_s yaw_deg pitch_deg\n0 0 0\n2 90 0\n", "level");
  expect_same(level.rotation_at(1.0), panorama_view_rotation(45 * kDeg, 0), 1e-12, "yaw 45");
  expect_same(level.rotation_at(0.5), panorama_view_rotation(22.5 * kDeg, 0), 1e-12, "yaw 22.5");
  expect_same(level.rotation_at(-5), panorama_view_rotation(0, 0), 0, "before");
  expect_same(level.rotation_at(9), panorama_view_rotation(90 * kDeg, 0), 0, "after");
  // The shorter way round: 170 -> -170 passes through 180, not 0.
  const HeadPoseTrack wrap = HeadPoseTrack::parse("t_s,yaw_deg,pitch_deg\n0,170,0\n1,-170,0\n", "wrap");
  expect_same(wrap.rotation_at(0.5), panorama_view_rotation(180 * kDeg, 0), 1e-12, "across 180");
}

TEST(HeadPoseTrack, RefusesBadTracksNamingTheFileAndLine) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      HeadPoseTrack::parse(text, "t.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const AssetError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("t.csv"), std::string::npos) << e.what();
    }
  };
  refused("t_s,yaw_deg,pitch_deg\n0,0,0\n2,10,0\n1,20,0\n", "line 4: t_s 1 is not after the line before's 2");
  refused("t_s,yaw_deg,pitch_deg\n0,0,0\n0,10,0\n", "line 3: t_s 0 is not after");
  refused("t_s,yaw_deg,pitch_deg\n0,north,0\n", "line 2: yaw_deg \"north\" is not a finite number");
  refused("t_s,yaw_deg,pitch_deg\n0,nan,0\n", "is not a finite number");
  refused("t_s,yaw_deg,pitch_deg\n0,1e999,0\n", "is not a finite number");
  refused("t_s,yaw_deg,pitch_deg\n0,0,95\n", "pitch_deg 95 is outside [-90, 90]");
  refused("t_s,qw,qx,qy,qz\n0,2,0,0,0\n", "the quaternion's length is 2");
  refused("t_s,qw,qx,qy,qz\n0,0,0,0,0\n", "the quaternion's length is 0");
  refused("t_s,yaw_deg,pitch_deg\n0,0\n", "line 2: 2 fields, where the header needs 3");
  refused("time,yaw,pitch\n0,0,0\n", "line 1: expected a header naming t_s");
  refused("t_s,yaw_deg,pitch_deg,qw,qx,qy,qz\n", "expected a header naming t_s and either");
  refused("t_s,t_s,yaw_deg,pitch_deg\n", "the column t_s is named twice");
  refused("# nothing\n\n", "no header line");
  refused("t_s,yaw_deg,pitch_deg\n# nothing yet\n", "no sample after the header");
}

TEST(HeadPoseTrack, RefusesAFileThatIsNotARegularFile) {
  const auto dir = test::scratch_dir("head-pose-dir");
  EXPECT_THROW(HeadPoseTrack::load(dir), AssetError);
  EXPECT_THROW(HeadPoseTrack::load(dir / "missing.csv"), AssetError);
}

TEST(HeadPoseTrack, DrivesThePanoramaSourcesViewAndPose) {
  // A 512 x 256 grey still, a track that looks right 90 degrees over 1 s and then up: each frame's
  // pose is the track's turn (yawed by the view's yaw_deg) placed as the sweep's would be.
  const auto dir = test::scratch_dir("head-pose-source");
  const std::filesystem::path still = dir / "grey.png";
  cv::imwrite(still.string(), cv::Mat(256, 512, CV_8UC3, cv::Scalar(100, 100, 100)));
  std::ofstream(dir / "track.csv") << "t_s,yaw_deg,pitch_deg\n0,0,0\n1,90,0\n2,90,60\n";
  SourceConfig config;
  config.type = SourceType::Panorama;
  config.pacing = ReplayPacing::Fast;
  config.panorama.file = still;
  config.panorama.position_m = {0.1, -0.2, 0.3};
  config.panorama.view.width = 32;
  config.panorama.view.height = 24;
  config.panorama.view.fps = 4;
  config.panorama.view.frames = 9;
  config.panorama.view.yaw_rad = 10 * kDeg;
  config.panorama.view.track = dir / "track.csv";
  PanoramaSource source(config);
  Frame frame;
  for (int k = 0; k < 9; ++k) {
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    ASSERT_TRUE(frame.meta.known_T_cam_world);
    const double t = k / 4.0;
    // The track's yaw plus the view's 10 degrees, at the track's pitch; the track's slerp at pitch 0
    // is the yaw's straight line, and between (1 s, yaw 90) and (2 s, pitch 60) a turn about x.
    const double yaw = (t <= 1 ? 90 * t : 90) + 10, pitch = t <= 1 ? 0 : 60 * (t - 1);
    const SE3 expected = panorama_view_pose(config.panorama.viewpoint(0), panorama_view_rotation(yaw * kDeg, pitch * kDeg));
    const SE3 got = *frame.meta.known_T_cam_world;
    for (size_t r = 0; r < 3; ++r) {
      EXPECT_NEAR(got.translation()[r], expected.translation()[r], 1e-12) << "frame " << k;
      for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(got.rotation()[r][c], expected.rotation()[r][c], 1e-12) << "frame " << k;
    }
  }
}

}  // namespace
}  // namespace arpipe
