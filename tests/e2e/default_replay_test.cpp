// End-to-end: the embedded default (configs/arpipe.toml over the build's default capture) through
// the real arpiped process, checked against the capture's ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "capture/recording/recording_reader.h"
#include "capture/sinks/png_sink.h"
#include "core/image/pixel_convert.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/default_capture_truth.h"

namespace fs = std::filesystem;
using namespace arpipe;
using test::tag_fully_visible;
using test::tag_out_of_view;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";
const fs::path kConfig = fs::path(ARPIPE_SOURCE_DIR) / "configs" / "arpipe.toml";
std::vector<nlohmann::json> read_jsonl(const fs::path& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

// ctest runs each test in its own process, in parallel, so each run gets its own output folder.
class DefaultReplay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    out_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ("default-replay-" + std::to_string(getpid()));
    fs::remove_all(out_);
    fs::create_directories(out_);
    ASSERT_TRUE(fs::exists(kCapture / "recording.json")) << "the build generates " << kCapture;
    const int code = test::run_to_exit(
        test::build_program("arpiped"),
        {"--config", kConfig.string(), "--set", "source.path=\"" + kCapture.string() + "\"", "--set",
         "sinks.png.dir=\"" + (out_ / "png").string() + "\"", "--set",
         "sinks.y4m.path=\"" + (out_ / "out.y4m").string() + "\"", "--set",
         "sinks.results.path=\"" + (out_ / "results.jsonl").string() + "\""},
        out_ / "logs", &stderr_);
    exit_code_ = code;
  }
  static void TearDownTestSuite() {
    if (!::testing::UnitTest::GetInstance()->Failed()) fs::remove_all(out_);
  }
  static inline fs::path out_;
  static inline std::string stderr_;
  static inline int exit_code_ = -1;
};

TEST_F(DefaultReplay, DaemonExitsCleanlyAtEndOfStream) { EXPECT_EQ(exit_code_, 0) << stderr_; }

TEST_F(DefaultReplay, EveryInputFrameGivesExactlyOneOutputFrame) {
  RecordingReader reader(kCapture);
  const size_t n = reader.frame_count();
  ASSERT_GT(n, 0u);
  const auto results = read_jsonl(out_ / "results.jsonl");
  ASSERT_EQ(results.size(), n);
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(results[i]["index"].get<uint64_t>(), i);
    EXPECT_EQ(results[i]["sequence"].get<uint64_t>(), reader.metadata(i).sequence);
    EXPECT_TRUE(fs::exists(PngSink::file_name(out_ / "png", i))) << i;
  }
  // Y4M: header line, then per frame "FRAME\n" and a 4:2:0 image.
  const auto& info = reader.info();
  const size_t frame_bytes = 6 + size_t(info.width) * info.height * 3 / 2;
  std::ifstream y4m(out_ / "out.y4m", std::ios::binary);
  std::string header;
  std::getline(y4m, header);
  EXPECT_EQ(header.rfind("YUV4MPEG2 W" + std::to_string(info.width) + " H" + std::to_string(info.height), 0), 0u)
      << header;
  const auto size = fs::file_size(out_ / "out.y4m");
  EXPECT_EQ(size, header.size() + 1 + n * frame_bytes);
}

// The acceptance criterion: where the tag is visible, the virtual object's anchor point
// (world origin) lands within 1 px of where the true pose puts it.
TEST_F(DefaultReplay, AnchorWithinOnePixelOfGroundTruth) {
  RecordingReader reader(kCapture);
  const auto& truth = reader.ground_truth();
  ASSERT_EQ(truth.size(), reader.frame_count());
  const auto results = read_jsonl(out_ / "results.jsonl");
  ASSERT_EQ(results.size(), truth.size());
  const CameraModel& model = reader.camera_model();
  int visible = 0, out_of_view = 0;
  double worst = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const SE3& T = truth[i].T_cam_world_mid;
    if (tag_fully_visible(model, T, 4.0)) {
      ++visible;
      ASSERT_EQ(results[i]["track_state"], "tracking") << "frame " << i;
      const auto expected = model.project(T * Vec3{0, 0, 0});
      ASSERT_TRUE(expected.has_value());
      const double dx = results[i]["anchor_px"][0].get<double>() - (*expected)[0];
      const double dy = results[i]["anchor_px"][1].get<double>() - (*expected)[1];
      const double err = std::hypot(dx, dy);
      worst = std::max(worst, err);
      EXPECT_LT(err, 1.0) << "frame " << i;
      EXPECT_TRUE(results[i]["virtual_layer_drawn"].get<bool>()) << "frame " << i;
    } else if (tag_out_of_view(model, T)) {
      ++out_of_view;
      EXPECT_EQ(results[i]["track_state"], "lost") << "frame " << i;
      EXPECT_FALSE(results[i]["virtual_layer_drawn"].get<bool>()) << "frame " << i;
    }
  }
  EXPECT_GT(visible, int(truth.size()) / 2);
  EXPECT_GE(out_of_view, 1) << "the default capture should include frames without the tag";
  RecordProperty("worst_anchor_error_px", std::to_string(worst));
}

// The composited PNGs: the cube covers the projection of its own centre, and pixels far from
// every virtual object are the camera frame unchanged (the pass-through must be exact).
TEST_F(DefaultReplay, CompositeShowsObjectAtTruePoseAndKeepsTheRest) {
  RecordingReader reader(kCapture);
  const auto& truth = reader.ground_truth();
  const CameraModel& model = reader.camera_model();
  int checked = 0;
  for (size_t i = 0; i < truth.size(); i += 7) {
    const SE3& T = truth[i].T_cam_world_mid;
    Frame input;
    reader.read(i, input);
    std::vector<uint8_t> rgb;
    to_rgb24(input, rgb);
    const cv::Mat png = cv::imread(PngSink::file_name(out_ / "png", i).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(png.empty()) << i;
    auto out_px = [&](int x, int y) { return png.at<cv::Vec3b>(y, x); };  // BGR
    auto in_px = [&](int x, int y) { return &rgb[(size_t(y) * input.width + x) * 3]; };
    // Image corner (2 px in): no virtual object can be there in the default trajectory.
    for (auto [x, y] : {std::pair{2, 2}, std::pair{input.width - 3, input.height - 3}}) {
      const auto o = out_px(x, y);
      const uint8_t* c = in_px(x, y);
      EXPECT_EQ(o[2], c[0]);
      EXPECT_EQ(o[1], c[1]);
      EXPECT_EQ(o[0], c[2]);
    }
    if (!tag_fully_visible(model, T, 4.0)) continue;
    // The builtin cube is 6 cm: its centre is 3 cm above the anchor.
    const auto centre = model.project(T * Vec3{0, 0, 0.03});
    ASSERT_TRUE(centre.has_value());
    const int x = int(std::lround((*centre)[0])), y = int(std::lround((*centre)[1]));
    const auto o = out_px(x, y);
    // Config colour is orange (0.8, 0.3, 0.1 linear): red clearly above blue whatever the shading.
    EXPECT_GT(int(o[2]), int(o[0]) + 40) << "frame " << i << " at " << x << "," << y;
    ++checked;
  }
  EXPECT_GT(checked, 3);
}

}  // namespace
