// The panorama source: frames, times, poses and the end of the stream as configured; hostile files
// refused at setup with the file named.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "capture/panorama/panorama_source.h"
#include "capture/panorama/panorama_view.h"
#include "core/environment/environment_layout.h"
#include "core/image/srgb.h"
#include "core/scene/asset_error.h"
#include "tests/capture/capture_test_support.h"

namespace arpipe {
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// A 512 x 256 panorama whose red channel is the column / 2 and green the row.
std::filesystem::path write_ramp_panorama(const std::filesystem::path& dir) {
  cv::Mat bgr(256, 512, CV_8UC3);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 512; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(0, uint8_t(y), uint8_t(x / 2));
  const std::filesystem::path file = dir / "ramp.png";
  cv::imwrite(file.string(), bgr);
  return file;
}

SourceConfig panorama_config(const std::filesystem::path& file) {
  SourceConfig config;
  config.type = SourceType::Panorama;
  config.pacing = ReplayPacing::Fast;
  config.panorama.file = file;
  config.panorama.position_m = {0.1, -0.2, 0.3};
  config.panorama.view.width = 64;
  config.panorama.view.height = 48;
  config.panorama.view.fps = 25;
  config.panorama.view.frames = 5;
  config.panorama.view.yaw_rad = 10 * kDeg;
  config.panorama.view.yaw_rad_per_s = 12 * kDeg;
  return config;
}

TEST(PanoramaSource, GivesTheConfiguredFramesWithTheirPoses) {
  const auto dir = test::scratch_dir("panorama-frames");
  const SourceConfig config = panorama_config(write_ramp_panorama(dir));
  PanoramaSource source(config);
  ASSERT_EQ(source.camera_model()->width(), 64);
  EXPECT_NEAR(source.camera_model()->fx(), 32.0, 1e-12);  // 90 degrees across 64 pixels
  EXPECT_EQ(source.frame_interval_ns(), 40'000'000);
  Frame frame;
  for (int k = 0; k < 5; ++k) {
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    EXPECT_EQ(frame.format, PixelFormat::RGB24);
    EXPECT_EQ(frame.meta.sequence, uint64_t(k));
    EXPECT_EQ(frame.meta.exposure_start_ns, k * 40'000'000);
    ASSERT_TRUE(frame.meta.known_T_cam_world);
    // The centre sits at position_m; the optical axis looks at yaw 10 + 12 t degrees right of the
    // panorama's centre (world +y), level.
    const SE3 T_world_cam = frame.meta.known_T_cam_world->inverse();
    for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(T_world_cam.translation()[i], config.panorama.position_m[i], 1e-12);
    const double yaw = (10 + 12 * k / 25.0) * kDeg;
    const Vec3 forward = T_world_cam.rotate({0, 0, 1});
    EXPECT_NEAR(forward[0], std::sin(yaw), 1e-12);
    EXPECT_NEAR(forward[1], std::cos(yaw), 1e-12);
    EXPECT_NEAR(forward[2], 0, 1e-12);
    // Pixel (32, 24), half a pixel right of and below the axis (cx = 31.5, cy = 23.5, f = 32),
    // shows the panorama there: red = column / 2, green = row.
    const uint8_t* pixel = frame.data.data() + 24 * frame.bytes_per_line + 3 * 32;
    const double off = std::atan(0.5 / 32);
    const double column = 255.5 + (yaw + off) / (2 * std::numbers::pi) * 512;
    const double row = 127.5 + std::atan(0.5 / std::hypot(32, 0.5)) / std::numbers::pi * 256;
    EXPECT_NEAR(pixel[0], column / 2, 1.0);
    EXPECT_NEAR(pixel[1], row, 1.0);
  }
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

TEST(PanoramaSource, RefusesBadFilesNamingThem) {
  const auto dir = test::scratch_dir("panorama-bad");
  const auto refused = [&](const std::filesystem::path& file, const std::string& expected,
                           PanoramaLayout layout = PanoramaLayout::Auto) {
    try {
      SourceConfig config = panorama_config(file);
      config.panorama.layout = layout;
      PanoramaSource source(config);
      ADD_FAILURE() << file << " was accepted";
    } catch (const AssetError& e) {
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused(dir / "missing.png", "no such file");
  // Square: not a mono panorama; a top/bottom pair by its shape (the "auto" layout), but not here
  // with its eyes 3:1.
  cv::imwrite((dir / "square.png").string(), cv::Mat(64, 64, CV_8UC3, cv::Scalar(1, 2, 3)));
  refused(dir / "square.png", "not 2:1", PanoramaLayout::Equirect);
  cv::imwrite((dir / "wide.png").string(), cv::Mat(64, 192, CV_8UC3, cv::Scalar(1, 2, 3)));
  refused(dir / "wide.png", "not 2:1");
  refused(dir / "wide.png", "not 1:1", PanoramaLayout::EquirectTopBottom);
  refused(dir / "wide.png", "not 4:1", PanoramaLayout::EquirectLeftRight);
  // A stereo viewpoint beside a mono one.
  cv::imwrite((dir / "mono.png").string(), cv::Mat(64, 128, CV_8UC3, cv::Scalar(1, 2, 3)));
  {
    SourceConfig config = panorama_config(dir / "mono.png");
    config.panorama.view.dwell_s = 1;
    config.panorama.viewpoints.push_back({dir / "square.png", Vec3{0, 0, 0}, 0, 1});
    try {
      PanoramaSource source(config);
      ADD_FAILURE() << "a mono and a stereo viewpoint were accepted together";
    } catch (const AssetError& e) {
      EXPECT_NE(std::string(e.what()).find("must all be mono or all stereo"), std::string::npos) << e.what();
    }
  }
  const std::filesystem::path ramp = write_ramp_panorama(dir);
  std::ifstream in(ramp, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream((dir / "cut.png").string(), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  refused(dir / "cut.png", "cannot be decoded");
  std::ofstream((dir / "text.png").string()) << "not an image at all\n";
  refused(dir / "text.png", "text.png");
}

TEST(PanoramaSource, TeleportsBetweenViewpointsEachWithItsPanoramaPoseSweepAndLight) {
  // Three viewpoints, grey 60, 120 and 200, each 0.5 s (2 frames at 4 frames/s), then back to the
  // first: each frame shows its viewpoint's image from its position and yaw, the sweep starting
  // again on arrival, and (light.source = "panorama") its own uniform light, L00 = L sqrt(4 pi).
  const auto dir = test::scratch_dir("panorama-viewpoints");
  SourceConfig config = panorama_config(dir / "0.png");
  config.panorama.view.fps = 4;
  config.panorama.view.frames = 8;
  config.panorama.view.dwell_s = 0.5;
  const std::array<int, 3> grey{60, 120, 200};
  for (int k = 0; k < 3; ++k) {
    const std::filesystem::path file = dir / (std::to_string(k) + ".png");
    cv::imwrite(file.string(), cv::Mat(256, 512, CV_8UC3, cv::Scalar(grey[k], grey[k], grey[k])));
    if (k > 0) config.panorama.viewpoints.push_back({file, Vec3{0.5 * k, 1.0, 0.2}, 30 * k * kDeg, 1.0});
  }
  ASSERT_EQ(config.panorama.viewpoint_count(), 3u);
  PanoramaSource source(config, true);
  Frame frame;
  for (int f = 0; f < 8; ++f) {
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    const int k = (f / 2) % 3;
    const PanoramaStop stop = panorama_stop_at(config.panorama, int64_t(f) * 250'000'000);
    EXPECT_EQ(stop.viewpoint, size_t(k)) << f;
    EXPECT_EQ(stop.arrived_ns, int64_t(f / 2) * 500'000'000) << f;
    ASSERT_EQ(frame.meta.viewpoint, k) << f;
    EXPECT_EQ(frame.data[3 * 10], grey[size_t(k)]) << f;
    const PanoramaViewpoint place = config.panorama.viewpoint(size_t(k));
    const SE3 T_world_cam = frame.meta.known_T_cam_world->inverse();
    for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(T_world_cam.translation()[i], place.position_m[i], 1e-12) << f;
    // The sweep's yaw (10 + 12 t degrees, t since arriving) plus the viewpoint's own yaw (a turn
    // counter-clockwise seen from above, so the view looks that much further left).
    const double yaw = (10 + 12 * (f % 2) * 0.25) * kDeg - place.yaw_rad;
    const Vec3 forward = T_world_cam.rotate({0, 0, 1});
    EXPECT_NEAR(forward[0], std::sin(yaw), 1e-12) << f;
    EXPECT_NEAR(forward[1], std::cos(yaw), 1e-12) << f;
    ASSERT_TRUE(frame.meta.environment_sh) << f;
    EXPECT_NEAR((*frame.meta.environment_sh)[0][0], srgb_decode(grey[size_t(k)] / 255.0) * std::sqrt(4 * std::numbers::pi), 1e-9) << f;
  }
}

}  // namespace
}  // namespace arpipe
