// Sinks on a disk that fills up and has room again (issue 18, finding 6): whole lines, whole
// frames and whole PNGs only; the outage logged once when it starts and once when writing resumes.
// The full disk is a file size limit (RLIMIT_FSIZE): the write across it is cut short, later ones fail.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "capture/recording/recording_reader.h"
#include "capture/sinks/png_sink.h"
#include "capture/sinks/recording_sink.h"
#include "capture/sinks/results_sink.h"
#include "capture/sinks/y4m_sink.h"
#include "capture_test_support.h"
#include "core/image/pixel_convert.h"
#include "sink_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

const std::string kFileTooLarge = std::strerror(EFBIG);

std::vector<uint64_t> result_indices(const fs::path& file) {
  std::vector<uint64_t> indices;
  std::istringstream in(read_file(file));
  for (std::string line; std::getline(in, line);) {
    nlohmann::json j;
    EXPECT_NO_THROW(j = nlohmann::json::parse(line)) << "not a whole JSON line: " << line;
    indices.push_back(j.value("index", uint64_t(999999)));
  }
  return indices;
}

TEST(SinkDiskFull, ResultsKeepWholeLinesAndResumeWhenSpaceReturns) {
  const fs::path file = scratch_dir("results-full") / "results.jsonl";
  std::vector<FrameContext> frames;
  for (uint64_t i = 0; i < 8; ++i) {
    frames.push_back(sink_context(4, 4, i));
    // Long lines, so that the room left is larger than the log message (the limit applies to the
    // file that captures stderr too).
    frames.back().record_timing("render", 1.0, std::string(500, 'x'));
  }
  const size_t line_bytes = ResultsSink::to_json_line(frames[0]).size() + 1;  // every line has this size
  testing::internal::CaptureStderr();
  {
    ResultsSink sink(ResultsSinkConfig{true, file});
    {
      // Room for two lines and half of the third: frame 2 is cut short, 3 and 4 find no room at all.
      FileSizeLimit full(2 * line_bytes + line_bytes / 2);
      for (uint64_t i = 0; i < 5; ++i) sink.consume(frames[i]);
      EXPECT_EQ(fs::file_size(file), 2 * line_bytes) << "the file must end at its last complete line";
    }
    for (uint64_t i = 5; i < 8; ++i) sink.consume(frames[i]);
    sink.flush();
    EXPECT_EQ(sink.failures(), 3u);
  }
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_EQ(result_indices(file), (std::vector<uint64_t>{0, 1, 5, 6, 7}));
  EXPECT_EQ(occurrences(log, "cannot write"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: cannot write frame 2: {}", file.string(), kFileTooLarge)), std::string::npos)
      << log;
  EXPECT_EQ(occurrences(log, "writing resumed"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: writing resumed at frame 5; 3 frames were lost (from frame 2)", file.string())),
            std::string::npos)
      << log;
}

TEST(SinkDiskFull, Y4mKeepsWholeFramesAndGoesOnWhenSpaceReturns) {
  const fs::path file = scratch_dir("y4m-full") / "video.y4m";
  constexpr int kWidth = 64, kHeight = 48;
  const std::string header = "YUV4MPEG2 W64 H48 F25:1 Ip A1:1 C420jpeg\n";
  const size_t frame_bytes = 6 + kWidth * kHeight * 3 / 2;
  std::vector<FrameContext> frames;
  for (uint64_t i = 0; i < 6; ++i) frames.push_back(sink_context(kWidth, kHeight, i));
  testing::internal::CaptureStderr();
  {
    Y4mSink sink(Y4mSinkConfig{true, file});
    {
      FileSizeLimit full(header.size() + frame_bytes + frame_bytes / 2);  // one and a half frames
      for (uint64_t i = 0; i < 3; ++i) sink.consume(frames[i]);
      EXPECT_EQ(fs::file_size(file), header.size() + frame_bytes) << "the video must end at its last complete frame";
    }
    for (uint64_t i = 3; i < 6; ++i) sink.consume(frames[i]);
    sink.flush();
    EXPECT_EQ(sink.frames_written(), 4u);
    EXPECT_EQ(sink.failures(), 2u);
  }
  const std::string log = testing::internal::GetCapturedStderr();
  const Y4mStream y4m = parse_y4m_stream(read_file(file), kWidth, kHeight);
  EXPECT_EQ(y4m.header, header);
  EXPECT_TRUE(y4m.markers_ok);
  EXPECT_EQ(y4m.torn_tail_bytes, 0u);
  ASSERT_EQ(y4m.frames.size(), 4u);
  // The frames are 0, 3, 4, 5, each with its own pixels.
  const uint64_t expected[] = {0, 3, 4, 5};
  for (size_t k = 0; k < 4; ++k) {
    std::vector<uint8_t> i420;
    rgb24_to_i420(frames[expected[k]].output.data.data(), kWidth, kWidth, kHeight, i420);
    EXPECT_TRUE(y4m.frames[k] == std::string(i420.begin(), i420.end())) << "frame " << k;
  }
  EXPECT_EQ(occurrences(log, "cannot write"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: cannot write frame 1: {}", file.string(), kFileTooLarge)), std::string::npos)
      << log;
  EXPECT_EQ(occurrences(log, "writing resumed"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: writing resumed at frame 3; 2 frames were lost (from frame 1)", file.string())),
            std::string::npos)
      << log;
}

TEST(SinkDiskFull, NoPartialPngStaysOnDiskAndLibpngPrintsNothing) {
  const fs::path dir = scratch_dir("png-full") / "png";
  constexpr int kWidth = 64, kHeight = 48;
  constexpr size_t kRoom = 4096;  // less than any of these PNGs, more than the log message
  std::vector<uint8_t> encoded;
  ASSERT_TRUE(cv::imencode(".png", cv::Mat(kHeight, kWidth, CV_8UC3, sink_context(kWidth, kHeight, 0).output.data.data()),
                           encoded));
  ASSERT_GT(encoded.size(), kRoom);
  testing::internal::CaptureStderr();
  {
    PngSink sink(PngSinkConfig{true, dir, 1});
    {
      FileSizeLimit full(kRoom);
      for (uint64_t i = 0; i < 3; ++i) sink.consume(sink_context(kWidth, kHeight, i));
      EXPECT_EQ(directory_names(dir), std::vector<std::string>{}) << "a partial PNG or a temporary was left";
    }
    for (uint64_t i = 3; i < 5; ++i) sink.consume(sink_context(kWidth, kHeight, i));
    EXPECT_EQ(sink.failures(), 3u);
  }
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_EQ(directory_names(dir), (std::vector<std::string>{"frame_000003.png", "frame_000004.png"}));
  for (uint64_t i = 3; i < 5; ++i) {
    const cv::Mat image = cv::imread(PngSink::file_name(dir, i).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << i;
    EXPECT_EQ(image.cols, kWidth);
    EXPECT_EQ(image.rows, kHeight);
  }
  EXPECT_EQ(log.find("libpng"), std::string::npos) << log;
  EXPECT_EQ(occurrences(log, "cannot write"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("cannot write frame 0: {}: {}", PngSink::file_name(dir, 0).string(), kFileTooLarge)),
            std::string::npos)
      << log;
  EXPECT_EQ(occurrences(log, "writing resumed"), 1u) << log;
  EXPECT_NE(log.find(fmt::format("{}: writing resumed at frame 3; 3 frames were lost (from frame 0)", dir.string())),
            std::string::npos)
      << log;
}

// The recording sink goes on after an outage too (the writer cuts a failed append back).
TEST(SinkDiskFull, RecordingGoesOnWhenSpaceReturns) {
  const fs::path dir = scratch_dir("recording-full") / "composited";
  constexpr int kWidth = 32, kHeight = 24;
  const size_t frame_bytes = size_t(kWidth) * kHeight * 3;
  auto camera = std::make_shared<const CameraModel>(small_camera(kWidth, kHeight));
  std::vector<FrameContext> frames;
  for (uint64_t i = 0; i < 4; ++i) {
    frames.push_back(sink_context(kWidth, kHeight, i));
    frames.back().camera_model = camera;
  }
  testing::internal::CaptureStderr();
  {
    RecordingSink sink(RecordingSinkConfig{true, dir});
    sink.consume(frames[0]);
    {
      FileSizeLimit full(frame_bytes + frame_bytes / 2);  // frames.bin has room for one and a half frames
      sink.consume(frames[1]);
      sink.consume(frames[2]);
    }
    sink.consume(frames[3]);
    sink.flush();
    EXPECT_EQ(sink.failures(), 2u);
  }
  const std::string log = testing::internal::GetCapturedStderr();
  RecordingReader reader(dir);
  ASSERT_EQ(reader.frame_count(), 2u);
  for (const auto& [k, index] : {std::pair<size_t, size_t>{0, 0}, {1, 3}}) {
    Frame frame;
    reader.read(k, frame);
    EXPECT_EQ(frame.meta.sequence, frames[index].camera.meta.sequence);
    EXPECT_TRUE(frame.data == frames[index].output.data) << "frame " << k;
  }
  EXPECT_EQ(occurrences(log, "cannot write frame 1"), 1u) << log;
  EXPECT_EQ(occurrences(log, "writing resumed at frame 3"), 1u) << log;
}

}  // namespace
}  // namespace arpipe
