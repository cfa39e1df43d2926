// A raw camera with a black level, end to end: the simulator writes a 10-bit Bayer capture whose
// no-light code is 64 (configs/sim/tag-static.toml, noise off), arpiped replays it and the PNG sink
// writes the developed camera picture. It must match the simulator's own linear image (its truth,
// sRGB-encoded) to within the demosaicer's error: the recording says its black level and gains
// (docs/FORMATS.md), and [source.raw] can say them for a camera that does not. Developed with the
// black level taken as 0 the same picture carries a grey veil of 64/1023 of full scale: the mean
// error bar below tells the two apart by a factor of more than 4.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording/recording_reader.h"
#include "capture/sinks/png_sink.h"
#include "core/image/srgb.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

// Mean over the picture of |developed - truth| in 8-bit sRGB levels, all three channels.
// The truth is the simulator's noise-free linear image (BGR float), clipped and sRGB-encoded.
double mean_error_levels(const fs::path& png, const fs::path& linear_pfm) {
  const cv::Mat developed = cv::imread(png.string(), cv::IMREAD_COLOR);
  const cv::Mat linear = cv::imread(linear_pfm.string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(developed.size(), linear.size());
  if (developed.empty() || developed.size() != linear.size()) return 1e9;
  double sum = 0;
  for (int y = 0; y < linear.rows; ++y)
    for (int x = 0; x < linear.cols; ++x)
      for (int c = 0; c < 3; ++c) {
        const double truth = 255 * srgb_encode(std::clamp(double(linear.at<cv::Vec3f>(y, x)[c]), 0.0, 1.0));
        sum += std::abs(double(developed.at<cv::Vec3b>(y, x)[c]) - truth);
      }
  return sum / (3.0 * linear.rows * linear.cols);
}

class RawDevelopment : public test::E2eTestDir {
 protected:
  // tag-static as a 10-bit GRBG raw sensor with black level 64, noise off, its linear image written.
  fs::path simulate_raw_capture() {
    std::ifstream in(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "tag-static.toml");
    std::stringstream text;
    text << in.rdbuf();
    std::string scene = text.str();
    auto replace = [&](const std::string& from, const std::string& to) {
      const size_t at = scene.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      scene.replace(at, from.size(), to);
    };
    replace("pixel_format = \"YUYV\"", "pixel_format = \"SGRBG10\"");
    replace("noise = true", "noise = false\nblack_level = 64");
    replace("[render]\n", "[render]\nwrite_linear = true\n");
    std::ofstream(dir_ / "scene.toml") << scene;
    const fs::path capture = dir_ / "raw-capture";
    std::string err;
    EXPECT_EQ(test::run_to_exit(test::build_program("arpipe"),
                                {"simulate", "--scene", (dir_ / "scene.toml").string(), "--out", capture.string(),
                                 "--frames", "2", "--samples", "4"},
                                dir_ / "sim-logs", &err),
              0)
        << err;
    return capture;
  }

  // Replays `capture` with nothing drawn; returns the mean error of frame 1 against its truth.
  double replay_error(const fs::path& capture, const std::string& extra, const std::string& name, std::string* log) {
    const fs::path config = dir_ / (name + ".toml");
    std::ofstream(config) << "[source]\npath = \"" << capture.string() << "\"\npacing = \"fast\"\n" << extra
                          << "[render]\nobjects = []\n[sinks.png]\ndir = \"" << (dir_ / name).string() << "\"\n";
    const int status = test::run_to_exit(test::build_program("arpiped"), {"--config", config.string()},
                                         dir_ / (name + "-logs"), log);
    EXPECT_EQ(status, 0) << *log;
    const RecordingReader reader(capture);
    return mean_error_levels(PngSink::file_name(dir_ / name, 1), capture / reader.ground_truth()[1].linear_image);
  }
};

// Demosaicing error on this scene (a tag's sharp edges on a smooth table) is under half a level
// on average (0.42 when written); the bar, 3 levels, is the demosaicer's mean error on its edge chart (0.0134 linear,
// docs/BENCHMARKS.md) at sRGB's steepest useful slope, rounded up. A veil of 64 codes is 0.063 of
// full scale: 10 to 20 levels where this scene lies.
TEST_F(RawDevelopment, ABlackLevelSaidByTheRecordingOrTheConfigDevelopsToTheTruth) {
  const fs::path capture = simulate_raw_capture();
  ASSERT_FALSE(HasFatalFailure());
  std::string log;
  const double from_recording = replay_error(capture, "", "recorded", &log);
  EXPECT_LT(from_recording, 3.0);
  EXPECT_NE(log.find("raw frames (SGRBG10): black 64/64/64/64"), std::string::npos) << log;
  EXPECT_NE(log.find("(the camera's)"), std::string::npos) << log;
  // A camera that says nothing, told by [source.raw]: the recording's values overridden.
  const double from_config =
      replay_error(capture, "[source.raw]\nblack_level = [64]\nwhite_balance = \"fixed\"\ngains = [1, 1, 1]\n",
                   "configured", &log);
  EXPECT_LT(from_config, 3.0);
  EXPECT_NE(log.find("(source.raw.gains)"), std::string::npos) << log;
  // The black level taken as 0: the veil shows.
  const double veiled = replay_error(capture, "[source.raw]\nblack_level = [0]\n", "veiled", &log);
  EXPECT_GT(veiled, 4 * 3.0) << "from the recording " << from_recording;
  std::printf("mean error in 8-bit levels: recorded black level %.3f, configured %.3f, black taken as 0 %.3f\n",
              from_recording, from_config, veiled);
}

}  // namespace
}  // namespace arpipe
