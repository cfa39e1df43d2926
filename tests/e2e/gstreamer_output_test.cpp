// The GStreamer sink in the real daemon: arpiped replays the default capture into a Matroska file of
// raw RGB through [sinks.gstreamer], and FFmpeg reads it back: every composited frame, in order,
// byte-exact against the PNG sink's frames, each at its exposure's time from the first.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/sinks/png_sink.h"
#include "tests/e2e/child_process.h"
#include "tests/e2e/e2e_test_dir.h"

namespace fs = std::filesystem;
using namespace arpipe;

namespace {

class GstreamerOutput : public test::E2eTestDir {};

std::string output_of(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  pclose(pipe);
  return out;
}

TEST_F(GstreamerOutput, EveryFrameOfAReplayByteExactAtItsExposureTime) {
  if (std::system("command -v ffprobe > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffprobe is not installed";
  const fs::path video = dir_ / "out.mkv";
  const fs::path config = write_config(test::kDefaultCapture, fmt::format("[sinks.gstreamer]\npipeline = \"appsrc name=arpipe ! "
                                                                         "matroskamux ! filesink location={}\"\n",
                                                                         video.string()));
  std::string said;
  ASSERT_EQ(test::run_to_exit(test::build_program("arpiped"), {"--config", config.string()}, dir_ / "log", &said), 0) << said;

  std::vector<int64_t> exposures;
  {
    std::ifstream results(dir_ / "results.jsonl");
    for (std::string line; std::getline(results, line);)
      exposures.push_back(nlohmann::json::parse(line)["exposure_start_ns"].get<int64_t>());
  }
  ASSERT_GT(exposures.size(), 10u);

  // Times: one per composited frame, at its exposure start from the first (Matroska: 1 ms ticks).
  std::istringstream times(output_of("ffprobe -v error -select_streams v:0 -show_entries frame=pts_time -of csv=p=0 " + video.string()));
  size_t n = 0;
  for (std::string line; std::getline(times, line); ++n) {
    ASSERT_LT(n, exposures.size()) << "more frames in the video than composited";
    EXPECT_NEAR(std::stod(line), double(exposures[n] - exposures[0]) * 1e-9, 0.0006) << "frame " << n;
  }
  EXPECT_EQ(n, exposures.size());

  // Pixels: the decoded video, frame by frame, equals the PNG sink's frames.
  const cv::Mat first = cv::imread(PngSink::file_name(dir_ / "png", 0).string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(first.empty());
  const size_t frame_bytes = size_t(first.cols) * size_t(first.rows) * 3;
  const fs::path raw = dir_ / "decoded.rgb";
  ASSERT_EQ(std::system(("ffmpeg -v error -i " + video.string() + " -f rawvideo -pix_fmt rgb24 " + raw.string()).c_str()), 0);
  ASSERT_EQ(fs::file_size(raw), frame_bytes * exposures.size());
  std::ifstream decoded(raw, std::ios::binary);
  std::string bytes(frame_bytes, '\0');
  for (size_t i = 0; i < exposures.size(); ++i) {
    ASSERT_TRUE(decoded.read(bytes.data(), std::streamsize(frame_bytes)));
    cv::Mat png = cv::imread(PngSink::file_name(dir_ / "png", i).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(png.empty()) << i;
    cv::cvtColor(png, png, cv::COLOR_BGR2RGB);
    ASSERT_TRUE(png.isContinuous());
    EXPECT_EQ(std::memcmp(png.data, bytes.data(), frame_bytes), 0) << "frame " << i << " differs from its PNG";
  }
}

}  // namespace
