// The real arpiped and arpipe on a "live" V4L2 camera: the stand-in library preloaded into the
// child process serves /dev/video-arpipe-e2e from the default capture, with faults injected.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_copy.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/default_capture_truth.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kCapture = fs::path(ARPIPE_BINARY_DIR) / "default-capture";
const fs::path kStandin = fs::path(ARPIPE_BINARY_DIR) / "tests" / "v4l2_standin" / "libarpipe-v4l2-standin.so";
constexpr const char* kDevice = "/dev/video-arpipe-e2e";

// The integer right after `label` in `text` (from `from` on), -1 when there is none.
int64_t number_after(const std::string& text, const std::string& label, size_t from = 0) {
  const size_t at = text.find(label, from);
  if (at == std::string::npos) return -1;
  size_t end = at + label.size();
  int64_t value = 0;
  bool digits = false;
  for (; end < text.size() && text[end] >= '0' && text[end] <= '9'; ++end, digits = true)
    value = value * 10 + (text[end] - '0');
  return digits ? value : -1;
}

class LiveV4L2 : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(ARPIPE_BINARY_DIR) / "e2e-out" / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  // The stand-in's config, and the environment that preloads it. The sanitizer build's runtime
  // must come first in the library list, which LD_PRELOAD breaks unless told not to check.
  std::vector<std::string> standin_env(const std::string& device_keys) {
    const fs::path config = dir_ / "standin.toml";
    std::ofstream(config) << "[[device]]\npath = \"" << kDevice << "\"\nrecording = \"" << kCapture.string() << "\"\n"
                          << device_keys << "\n";
    const char* asan = std::getenv("ASAN_OPTIONS");
    return {"LD_PRELOAD=" + kStandin.string(), "ARPIPE_V4L2_STANDIN=" + config.string(),
            std::string("ASAN_OPTIONS=") + (asan ? std::string(asan) + ":" : "") + "verify_asan_link_order=0"};
  }
  size_t result_lines() { return test::count_lines(dir_ / "results.jsonl"); }
  fs::path dir_;
};

// Drops, a stall, an EAGAIN storm, a corrupt buffer and an unplug with replug: the daemon runs
// through all of it and exits 0 after its 30 frames. A live source drops the oldest queued frame
// when processing falls behind (the stand-in serves as fast as buffers come back), so every frame
// in is either a result or a counted queue drop, and every frame lost before the pipeline is a
// counted sequence gap: the driver's skips, the corrupt buffer, and those missed while unplugged.
TEST_F(LiveV4L2, DaemonRunsThroughFaultsOnALiveCamera) {
  const auto env = standin_env(
      "pacing = \"fast\"\n"
      "[[device.fault]]\nframe = 5\nkind = \"drop\"\ncount = 2\n"
      "[[device.fault]]\nframe = 10\nkind = \"eagain\"\ncount = 20\n"
      "[[device.fault]]\nframe = 14\nkind = \"error_buffer\"\n"
      "[[device.fault]]\nframe = 18\nkind = \"stall\"\nduration_ms = 400\n"
      "[[device.fault]]\nframe = 24\nkind = \"unplug\"\nreplug_after_ms = 300\n");
  const fs::path config = dir_ / "arpipe.toml";
  std::ofstream(config) << "[source]\ntype = \"v4l2\"\ndevice = \"" << kDevice << "\"\ncamera_model = \""
                        << (kCapture / "camera.cameramodel").string() << "\"\n"
                        << "frame_timeout_ms = 300\nreconnect_min_ms = 50\n"
                        << "[pipeline]\nmax_frames = 30\n"
                        << "[sinks.results]\npath = \"" << (dir_ / "results.jsonl").string() << "\"\n";
  std::string err;
  const int status =
      test::run_to_exit(test::build_program("arpiped"), {"--config", config.string()}, dir_ / "logs", &err, env);
  EXPECT_EQ(status, 0) << err;
  // The daemon's last lines: "30 frames in, 13 out ...; sequence gaps 7, queue drops 17, ..." and
  // "camera: connected, frames 30, sequence gaps 2, timeouts 1, EAGAIN 20, bad buffers 1, ...".
  const size_t metrics = err.rfind(" frames in, ");
  const size_t camera = err.rfind("camera: connected");
  ASSERT_NE(metrics, std::string::npos) << err;
  ASSERT_NE(camera, std::string::npos) << err;
  const std::string metrics_line = err.substr(err.rfind('\n', metrics) + 1);
  const std::string camera_line = err.substr(camera);
  EXPECT_EQ(number_after(metrics_line, "info: "), 30) << metrics_line;
  EXPECT_EQ(number_after(metrics_line, " frames in, ") + number_after(metrics_line, "queue drops "), 30)
      << "frames out + queue drops";
  // Every frame out is a results line, or one the results sink dropped when it fell behind (a
  // slow machine): the daemon's last word on that sink says how many.
  const size_t sink_drops = err.find("sinks.results: took ");
  const int64_t results_dropped =
      sink_drops == std::string::npos ? 0 : number_after(err, " dropped ", sink_drops);
  EXPECT_EQ(int64_t(result_lines()) + results_dropped, number_after(metrics_line, " frames in, ")) << err;
  if (sink_drops != std::string::npos) {
    EXPECT_EQ(number_after(err, "sinks.results: took ", sink_drops), int64_t(result_lines())) << err;
  }
  EXPECT_EQ(number_after(camera_line, "sequence gaps "), 2) << "the driver's drop fault";
  EXPECT_GE(number_after(camera_line, "timeouts "), 1) << "the 400 ms stall against a 300 ms timeout";
  EXPECT_EQ(number_after(camera_line, "EAGAIN "), 20) << "the EAGAIN storm";
  EXPECT_EQ(number_after(camera_line, "bad buffers "), 1) << "the corrupt buffer";
  EXPECT_EQ(number_after(metrics_line, "sequence gaps "),
            number_after(camera_line, "sequence gaps ") + number_after(camera_line, "bad buffers ") +
                number_after(camera_line, "frames missed while away "));
  EXPECT_NE(err.find("camera lost"), std::string::npos) << err;
  EXPECT_NE(err.find("camera back"), std::string::npos) << err;
  EXPECT_NE(err.find("no frame within 300 ms"), std::string::npos) << err;
  EXPECT_NE(err.find("disconnects 1, reconnects 1"), std::string::npos) << err;
}

// arpipe cameras lists the stand-in's formats and controls; arpipe record writes a recording whose
// frames and metadata are the served recording's.
TEST_F(LiveV4L2, CamerasListsAndRecordWritesTheCamerasFramesAndMetadata) {
  const auto env = standin_env("pacing = \"fast\"\nformats = [\"native\", \"MJPG\"]\n");
  std::string err;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpipe"), {"cameras", "--v4l2-only", kDevice}, dir_ / "cameras",
                              &err, env),
            0)
      << err;
  const std::string listing = test::read_text(dir_ / "cameras" / "stdout.txt");
  EXPECT_NE(listing.find("YUYV 640x480 @ 30 fps"), std::string::npos) << listing;
  EXPECT_NE(listing.find("MJPG 640x480 @ 30 fps"), std::string::npos) << listing;
  EXPECT_NE(listing.find("Exposure"), std::string::npos) << listing;

  const fs::path out = dir_ / "recorded";
  ASSERT_EQ(test::run_to_exit(test::build_program("arpipe"),
                              {"record", "--camera", std::string("v4l2:") + kDevice, "--out", out.string(), "--frames",
                               "12", "--format", "YUYV"},
                              dir_ / "record", &err, env),
            0)
      << err;
  const RecordingReader recorded(out);
  const RecordingReader truth(kCapture);
  ASSERT_EQ(recorded.frame_count(), 12u);
  for (size_t i = 0; i < 12; ++i) {
    Frame a, b;
    recorded.read(i, a);
    truth.read(i, b);
    EXPECT_EQ(a.data, b.data) << "frame " << i;
    // V4L2 timestamps are timevals: exact to the microsecond, truncated.
    EXPECT_EQ(a.meta.exposure_start_ns, b.meta.exposure_start_ns / 1000 * 1000) << "frame " << i;
    EXPECT_EQ(a.meta.exposure_ns, b.meta.exposure_ns) << "frame " << i;
    EXPECT_EQ(a.meta.sequence, b.meta.sequence) << "frame " << i;
  }
  EXPECT_NE(recorded.info().source.find("v4l2:"), std::string::npos);
}

}  // namespace

namespace {

// The default capture's first `frames` frames as a raw sensor would give them: each pixel's CFA
// channel (GRBG, MIPI-packed 10-bit) of its linear value, with the ground truth.
fs::path bayer_copy_of_default_capture(const fs::path& dir, size_t frames) {
  const fs::path out = dir / "bayer-capture";
  copy_recording_as(kCapture, out, PixelFormat::SGRBG10P, frames,
                    "the default capture as a GRBG 10-bit MIPI-packed raw sensor");
  return out;
}

}  // namespace

// Issue 24: a raw Bayer camera. The stand-in serves the mosaic as it is, the V4L2 source passes it
// on raw, the source measures its grey-world gains (capture/raw_colour_source.h), the tracker and
// the light stage develop it (core/image/bayer.h), and the daemon tracks
// the tag to the bar the YUYV capture meets (the anchor within 1 px of the true pose) and
// composites the cube on every frame that sees the whole tag.
TEST_F(LiveV4L2, ARawBayerCameraIsTrackedAndComposited) {
  constexpr size_t kFrames = 12;
  const fs::path bayer = bayer_copy_of_default_capture(dir_, kFrames);
  const fs::path standin_config = dir_ / "standin.toml";
  std::ofstream(standin_config) << "[[device]]\npath = \"" << kDevice << "\"\nrecording = \"" << bayer.string()
                                << "\"\nformats = [\"native\"]\npacing = \"fast\"\n";
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::vector<std::string> env{"LD_PRELOAD=" + kStandin.string(), "ARPIPE_V4L2_STANDIN=" + standin_config.string(),
                                     std::string("ASAN_OPTIONS=") + (asan ? std::string(asan) + ":" : "") +
                                         "verify_asan_link_order=0"};
  std::string err;
  const int status = test::run_to_exit(
      test::build_program("arpiped"),
      {"--config", (fs::path(ARPIPE_SOURCE_DIR) / "configs" / "arpipe.toml").string(), "--set", "source.type=\"v4l2\"",
       "--set", std::string("source.device=\"") + kDevice + "\"", "--set", "source.pixel_format=\"SGRBG10P\"", "--set",
       "source.camera_model=\"" + (kCapture / "camera.cameramodel").string() + "\"", "--set",
       "pipeline.max_frames=" + std::to_string(kFrames), "--set",
       "sinks.png.dir=\"" + (dir_ / "png").string() + "\"", "--set", "sinks.y4m.path=\"" + (dir_ / "out.y4m").string() + "\"",
       "--set", "sinks.results.path=\"" + (dir_ / "results.jsonl").string() + "\""},
      dir_ / "logs", &err, env);
  ASSERT_EQ(status, 0) << err;
  EXPECT_NE(err.find("streaming SGRBG10P 640x480"), std::string::npos) << err;
  EXPECT_NE(err.find("(one copy a frame from the mapped buffer into recycled frames)"), std::string::npos) << err;
  // A V4L2 sensor says nothing of its colours: the frames develop with grey-world gains.
  EXPECT_NE(err.find("(grey world, per frame)"), std::string::npos) << err;
  const RecordingReader reader(kCapture);
  const CameraModel& model = reader.camera_model();
  std::ifstream results(dir_ / "results.jsonl");
  std::string line;
  int checked = 0;
  while (std::getline(results, line)) {
    const auto r = nlohmann::json::parse(line);
    const size_t i = r["sequence"].get<size_t>();
    ASSERT_LT(i, kFrames);
    const SE3& T = reader.ground_truth()[i].T_cam_world_mid;
    if (!test::tag_fully_visible(model, T, 4.0)) continue;
    const auto expected = model.project(T * Vec3{0, 0, 0});
    ASSERT_TRUE(expected.has_value());
    ASSERT_EQ(r["track_state"], "tracking") << "frame " << i;
    const double err_px = std::hypot(r["anchor_px"][0].get<double>() - (*expected)[0],
                                     r["anchor_px"][1].get<double>() - (*expected)[1]);
    EXPECT_LT(err_px, 1.0) << "frame " << i;
    EXPECT_TRUE(r["virtual_layer_drawn"].get<bool>()) << "frame " << i;
    ++checked;
  }
  EXPECT_GE(checked, 3) << err;  // a live camera's queue may drop frames
}
