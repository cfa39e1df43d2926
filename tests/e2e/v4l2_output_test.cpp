// The V4L2 output sink in the real daemon: arpiped (the stand-in preloaded) replays the default
// capture into the output node of a stand-in loopback pair, and FFmpeg's v4l2 input, in its own
// process with the stand-in preloaded, reads the paired capture node: every composited frame, in
// order, byte-exact against the PNG sink's frames (RGB24) or their YUYV conversion, each with its
// exposure start as the buffer timestamp. Every wait has a bound.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <link.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/sinks/png_sink.h"
#include "core/image/pixel_convert.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

const fs::path kStandinLibrary = fs::path(ARPIPE_BINARY_DIR) / "tests" / "v4l2_standin" / "libarpipe-v4l2-standin.so";
constexpr const char* kOutputNode = "/dev/video-arpipe-e2e-out";
constexpr const char* kCaptureNode = "/dev/video-arpipe-e2e-cap";

// The full path of a program on PATH ("" when there is none).
std::string program_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    const fs::path candidate = fs::path(dir) / name;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

// The sanitizer runtime this test runs with ("" in a plain build). FFmpeg is not built with it, and
// the stand-in of a sanitizer build needs it: it is preloaded first, as docs/V4L2_STANDIN.md says.
std::string sanitizer_runtime() {
#if defined(__SANITIZE_ADDRESS__)
  std::string found;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        const std::string name = info->dlpi_name != nullptr ? info->dlpi_name : "";
        if (name.find("libasan.so") != std::string::npos) *static_cast<std::string*>(out) = name;
        return 0;
      },
      &found);
  return found;
#else
  return "";
#endif
}

class V4l2Output : public test::E2eTestDir {
 protected:
  // The stand-in's loopback pair, and the environment that preloads it (into both processes). The
  // sanitizer build's runtime must come first in the library list, which LD_PRELOAD breaks unless
  // told not to check.
  std::vector<std::string> standin_env() {
    const fs::path config = dir_ / "standin.toml";
    std::ofstream(config) << "[[loopback]]\noutput = \"" << kOutputNode << "\"\ncapture = \"" << kCaptureNode
                          << "\"\nspool = \"spool\"\n";
    const char* asan = std::getenv("ASAN_OPTIONS");
    return {"LD_PRELOAD=" + kStandinLibrary.string(), "ARPIPE_V4L2_STANDIN=" + config.string(),
            std::string("ASAN_OPTIONS=") + (asan ? std::string(asan) + ":" : "") + "verify_asan_link_order=0"};
  }

  // Runs arpiped with [sinks.v4l2] (and the PNG, Y4M and results sinks of write_config), and, once
  // the writer has set its format, ffmpeg reading `frames` frames of `pixel_format` from the
  // capture node into frames.raw (the bytes) and frames.md5 (framemd5: one pts per frame, in µs,
  // the buffer timestamps kept by -copyts). Both must exit 0 within their bounds.
  void run_daemon_and_reader(const std::string& sink_format, const std::string& pixel_format, size_t frames,
                             const std::string& extra_config = "") {
    const std::string ffmpeg = program_path("ffmpeg");
    ASSERT_FALSE(ffmpeg.empty());
    const auto env = standin_env();
    const fs::path config = write_config(
        test::kDefaultCapture,
        fmt::format("[sinks.v4l2]\ndevice = \"{}\"\nformat = \"{}\"\n{}", kOutputNode, sink_format, extra_config));
    test::ChildProcess daemon(test::build_program("arpiped"), {"--config", config.string()}, dir_ / "daemon", env);
    // The capture node has a format once the writer set one (as v4l2loopback with exclusive_caps=1).
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!fs::exists(dir_ / "spool" / "format") && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_TRUE(fs::exists(dir_ / "spool" / "format")) << "the sink set no format within 120 s\n" << daemon.stderr_text();
    const std::string count = std::to_string(frames);
    std::vector<std::string> reader_env = env;
    if (const std::string runtime = sanitizer_runtime(); !runtime.empty())
      reader_env[0] = "LD_PRELOAD=" + runtime + " " + kStandinLibrary.string();
    test::ChildProcess reader(ffmpeg,
                              {"-nostdin", "-hide_banner", "-loglevel", "error", "-copyts", "-f", "v4l2",
                               "-pixel_format", pixel_format, "-i", kCaptureNode,
                               "-map", "0:v", "-frames:v", count, "-c:v", "copy", "-f", "rawvideo", "-y", (dir_ / "frames.raw").string(),
                               "-map", "0:v", "-frames:v", count, "-c:v", "copy", "-f", "framemd5", "-y", (dir_ / "frames.md5").string()},
                              dir_ / "ffmpeg", reader_env);
    const int daemon_status = daemon.wait(std::chrono::seconds(600));
    ASSERT_TRUE(daemon_status != -1 && WIFEXITED(daemon_status) && WEXITSTATUS(daemon_status) == 0)
        << "arpiped: status " << daemon_status << "\n" << daemon.stderr_text();
    // Everything is written: ffmpeg has all it waits for (a missing frame shows as a timeout).
    const int reader_status = reader.wait(std::chrono::seconds(60));
    ASSERT_TRUE(reader_status != -1 && WIFEXITED(reader_status) && WEXITSTATUS(reader_status) == 0)
        << "ffmpeg: status " << reader_status << " (-1: still waiting for frames after 60 s)\n" << reader.stderr_text();
  }

  // exposure_start_ns of every composited frame, from the results sink.
  std::vector<int64_t> exposures() const {
    std::vector<int64_t> out;
    std::ifstream results(dir_ / "results.jsonl");
    for (std::string line; std::getline(results, line);)
      out.push_back(nlohmann::json::parse(line)["exposure_start_ns"].get<int64_t>());
    return out;
  }

  // The pts column of frames.md5 (after "#tb 0: 1/1000000").
  std::vector<int64_t> reader_pts() const {
    std::vector<int64_t> out;
    std::ifstream md5(dir_ / "frames.md5");
    bool microseconds = false;
    for (std::string line; std::getline(md5, line);) {
      if (line.starts_with("#tb 0: 1/1000000")) microseconds = true;
      if (line.empty() || line[0] == '#') continue;
      std::stringstream fields(line);
      std::string stream, dts, pts;
      std::getline(fields, stream, ',');
      std::getline(fields, dts, ',');
      std::getline(fields, pts, ',');
      out.push_back(std::stoll(pts));
    }
    EXPECT_TRUE(microseconds) << "framemd5's time base is not 1/1000000";
    return out;
  }

  // The PNG sink's frame `index`, as packed RGB24.
  cv::Mat png_rgb(size_t index) const {
    cv::Mat png = cv::imread(PngSink::file_name(dir_ / "png", index).string(), cv::IMREAD_COLOR);
    if (!png.empty()) cv::cvtColor(png, png, cv::COLOR_BGR2RGB);
    return png;
  }

  size_t spool_frames() const {
    size_t n = 0;
    for (const auto& entry : fs::directory_iterator(dir_ / "spool"))
      if (entry.path().extension() == ".frame") ++n;
    return n;
  }
};

TEST_F(V4l2Output, FfmpegReadsEveryCompositedFrameByteExactAtItsExposureStart) {
  if (program_path("ffmpeg").empty()) GTEST_SKIP() << "ffmpeg is not installed";
  const size_t frames = test::count_lines(test::kDefaultCapture / "frames.jsonl");
  ASSERT_GT(frames, 10u);
  run_daemon_and_reader("rgb24", "rgb24", frames);
  if (HasFatalFailure()) return;

  const std::vector<int64_t> exposure = exposures();
  ASSERT_EQ(exposure.size(), frames) << "every frame of the replay is composited";
  EXPECT_EQ(spool_frames(), frames) << "the sink wrote each composited frame once";

  // Times: the buffer timestamp is the exposure start, to the microsecond (a timeval), truncated.
  const std::vector<int64_t> pts = reader_pts();
  ASSERT_EQ(pts.size(), frames);
  for (size_t i = 0; i < frames; ++i) EXPECT_EQ(pts[i], exposure[i] / 1000) << "frame " << i;

  // Pixels: what ffmpeg read, frame by frame, equals the PNG sink's frames.
  const cv::Mat first = png_rgb(0);
  ASSERT_FALSE(first.empty());
  const size_t frame_bytes = size_t(first.cols) * size_t(first.rows) * 3;
  ASSERT_EQ(fs::file_size(dir_ / "frames.raw"), frame_bytes * frames);
  std::ifstream raw(dir_ / "frames.raw", std::ios::binary);
  std::string bytes(frame_bytes, '\0');
  for (size_t i = 0; i < frames; ++i) {
    ASSERT_TRUE(raw.read(bytes.data(), std::streamsize(frame_bytes)));
    const cv::Mat png = png_rgb(i);
    ASSERT_FALSE(png.empty()) << i;
    ASSERT_TRUE(png.isContinuous());
    EXPECT_EQ(std::memcmp(png.data, bytes.data(), frame_bytes), 0) << "frame " << i << " differs from its PNG";
  }
}

// YUYV, what browsers and video calls take: each frame is the PNG's conversion by the project's
// converter (BT.601 limited range), byte for byte. A shorter run (12 frames).
TEST_F(V4l2Output, FfmpegReadsYuyvFramesThatAreTheCompositesConversion) {
  if (program_path("ffmpeg").empty()) GTEST_SKIP() << "ffmpeg is not installed";
  constexpr size_t kFrames = 12;
  run_daemon_and_reader("yuyv", "yuyv422", kFrames, "[pipeline]\nmax_frames = 12\n");
  if (HasFatalFailure()) return;
  const std::vector<int64_t> exposure = exposures();
  ASSERT_EQ(exposure.size(), kFrames);
  const std::vector<int64_t> pts = reader_pts();
  ASSERT_EQ(pts.size(), kFrames);
  for (size_t i = 0; i < kFrames; ++i) EXPECT_EQ(pts[i], exposure[i] / 1000) << "frame " << i;

  const cv::Mat first = png_rgb(0);
  ASSERT_FALSE(first.empty());
  const int width = first.cols & ~1, height = first.rows;
  const size_t frame_bytes = size_t(width) * 2 * size_t(height);
  ASSERT_EQ(fs::file_size(dir_ / "frames.raw"), frame_bytes * kFrames);
  std::ifstream raw(dir_ / "frames.raw", std::ios::binary);
  std::vector<uint8_t> bytes(frame_bytes), expected(frame_bytes);
  for (size_t i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(raw.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(frame_bytes)));
    const cv::Mat png = png_rgb(i);
    ASSERT_FALSE(png.empty()) << i;
    rgb24_to_yuyv(png.data, png.step[0], width, height, expected.data(), size_t(width) * 2);
    EXPECT_EQ(bytes, expected) << "frame " << i;
  }
}

}  // namespace
