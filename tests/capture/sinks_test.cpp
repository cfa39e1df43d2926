// Sink tests: Y4M streams checked by our own parser and by ffprobe, BT.601 values from the formula,
// PNGs read back by OpenCV, results JSON against CameraModel::project, recordings read back, errors.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <array>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/sinks/png_sink.h"
#include "capture/sinks/recording_sink.h"
#include "capture/sinks/results_sink.h"
#include "capture/sinks/y4m_sink.h"
#include "capture_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

struct Rgb {
  uint8_t r, g, b;
};

// A context whose composited output is RGB24 with the given stride (0: the minimum), each pixel
// coloured by pixel(x, y); padding bytes are 0xEE so a sink that reads them shows it.
template <typename PixelFn>
FrameContext context_with_output(int width, int height, uint64_t index, PixelFn pixel, size_t bytes_per_line = 0) {
  FrameContext ctx;
  ctx.input_index = index;
  ctx.camera.meta.sequence = 1000 + index;
  ctx.camera.meta.exposure_start_ns = 2'000'000'000 + int64_t(index) * 40'000'000;
  ctx.camera.meta.exposure_ns = 5'000'000;
  ctx.camera.meta.frame_duration_ns = 40'000'000;
  ctx.output.format = PixelFormat::RGB24;
  ctx.output.width = width;
  ctx.output.height = height;
  ctx.output.bytes_per_line = bytes_per_line ? bytes_per_line : size_t(width) * 3;
  ctx.output.data.assign(ctx.output.bytes_per_line * size_t(height), 0xEE);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Rgb c = pixel(x, y);
      uint8_t* p = ctx.output.data.data() + size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3;
      p[0] = c.r, p[1] = c.g, p[2] = c.b;
    }
  ctx.output.meta = ctx.camera.meta;
  return ctx;
}

FrameContext uniform_context(int width, int height, uint64_t index, Rgb colour) {
  return context_with_output(width, height, index, [&](int, int) { return colour; });
}

// ---------------------------------------------------------------------------------------------
// Y4M

// BT.601 limited range from its definition: Kr = 0.299, Kb = 0.114, luma scaled to 16..235 and
// colour differences to 16..240 around 128 (ITU-R BT.601-7, section 2.5).
std::array<double, 3> bt601_limited_yuv(Rgb c) {
  const double kr = 0.299, kb = 0.114, kg = 1 - kr - kb;
  const double r = c.r / 255.0, g = c.g / 255.0, b = c.b / 255.0;
  const double luma = kr * r + kg * g + kb * b;
  const double pb = (b - luma) / (2 * (1 - kb));  // -0.5..0.5
  const double pr = (r - luma) / (2 * (1 - kr));
  return {16 + 219 * luma, 128 + 224 * pb, 128 + 224 * pr};
}

struct Y4mFile {
  std::string header;                      // without the newline
  std::vector<std::vector<uint8_t>> frames;  // I420 payloads of the complete frames
  size_t torn_tail_bytes = 0;              // bytes after the last complete frame
  bool markers_ok = true;                  // every frame started with "FRAME\n"
};

// Our own reader for the subset the sink writes: header line, then "FRAME\n" + W*H*3/2 bytes each.
Y4mFile parse_y4m(const std::string& bytes, int width, int height) {
  Y4mFile out;
  const size_t header_end = bytes.find('\n');
  if (header_end == std::string::npos) return out;
  out.header = bytes.substr(0, header_end);
  const size_t payload = size_t(width) * height * 3 / 2;
  size_t at = header_end + 1;
  while (at + 6 + payload <= bytes.size()) {
    if (bytes.compare(at, 6, "FRAME\n") != 0) out.markers_ok = false;
    out.frames.emplace_back(bytes.begin() + long(at + 6), bytes.begin() + long(at + 6 + payload));
    at += 6 + payload;
  }
  out.torn_tail_bytes = bytes.size() - at;
  return out;
}

// Runs a command and returns its standard output.
std::string run_command(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[256];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  pclose(pipe);
  return out;
}

bool have_ffprobe() { return std::system("command -v ffprobe > /dev/null 2>&1") == 0; }

// key=value lines of ffprobe's default writer.
std::map<std::string, std::string> ffprobe_stream(const fs::path& file) {
  const std::string text = run_command(fmt::format(
      "ffprobe -v error -count_frames -select_streams v:0 "
      "-show_entries stream=codec_name,width,height,pix_fmt,r_frame_rate,nb_read_frames "
      "-of default=noprint_wrappers=1 '{}'",
      file.string()));
  std::map<std::string, std::string> fields;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    if (const size_t eq = line.find('='); eq != std::string::npos) fields[line.substr(0, eq)] = line.substr(eq + 1);
    start = end + 1;
  }
  return fields;
}

const std::vector<Rgb> kTestColours = {{200, 100, 50}, {0, 0, 0},   {255, 255, 255}, {255, 0, 0},
                                       {0, 255, 0},    {0, 0, 255}, {17, 230, 140}};

TEST(Y4mSink, WritesAValidStreamWithTheRightHeaderSizeAndFrameCount) {
  const fs::path file = scratch_dir("y4m-valid") / "video.y4m";
  constexpr int kWidth = 64, kHeight = 48;
  {
    Y4mSink sink(Y4mSinkConfig{true, file});
    for (size_t i = 0; i < kTestColours.size(); ++i) {
      FrameContext ctx = uniform_context(kWidth, kHeight, i, kTestColours[i]);
      ctx.camera.meta.frame_duration_ns = 33'366'700;  // 29.97 fps: 1e9 / 33366700 = 10000000 / 333667
      sink.consume(ctx);
    }
    EXPECT_EQ(sink.frames_written(), kTestColours.size());
  }
  const std::string expected_header = "YUV4MPEG2 W64 H48 F10000000:333667 Ip A1:1 C420jpeg";
  const std::string bytes = read_file(file);
  EXPECT_EQ(bytes.size(), expected_header.size() + 1 + kTestColours.size() * (6 + kWidth * kHeight * 3 / 2));
  const Y4mFile y4m = parse_y4m(bytes, kWidth, kHeight);
  EXPECT_EQ(y4m.header, expected_header);
  EXPECT_TRUE(y4m.markers_ok);
  EXPECT_EQ(y4m.frames.size(), kTestColours.size());
  EXPECT_EQ(y4m.torn_tail_bytes, 0u);

  if (!have_ffprobe()) GTEST_SKIP() << "ffprobe not installed; checked with our own parser only";
  auto stream = ffprobe_stream(file);
  EXPECT_EQ(stream["codec_name"], "rawvideo");
  EXPECT_EQ(stream["width"], "64");
  EXPECT_EQ(stream["height"], "48");
  EXPECT_EQ(stream["pix_fmt"], "yuv420p");
  EXPECT_EQ(stream["r_frame_rate"], "10000000/333667");
  EXPECT_EQ(stream["nb_read_frames"], std::to_string(kTestColours.size()));
}

TEST(Y4mSink, FrameRateComesFromTheFrameDuration) {
  struct Case {
    int64_t frame_duration_ns;
    std::string rate;
  };
  // 40 ms = 25 fps exactly; 1/60 s rounded to 16666667 ns; unknown (0) means 30 fps.
  for (const auto& [duration, rate] : {Case{40'000'000, "F25:1"}, Case{16'666'667, "F1000000000:16666667"},
                                       Case{0, "F30:1"}}) {
    const fs::path file = scratch_dir("y4m-rate") / "video.y4m";
    {
      Y4mSink sink(Y4mSinkConfig{true, file});
      FrameContext ctx = uniform_context(8, 8, 0, {1, 2, 3});
      ctx.camera.meta.frame_duration_ns = duration;
      sink.consume(ctx);
    }
    EXPECT_EQ(parse_y4m(read_file(file), 8, 8).header, "YUV4MPEG2 W8 H8 " + rate + " Ip A1:1 C420jpeg");
  }
}

TEST(Y4mSink, UniformColoursBecomeBt601LimitedRangeYuv) {
  const fs::path file = scratch_dir("y4m-values") / "video.y4m";
  constexpr int kWidth = 16, kHeight = 8;
  {
    Y4mSink sink(Y4mSinkConfig{true, file});
    for (size_t i = 0; i < kTestColours.size(); ++i) sink.consume(uniform_context(kWidth, kHeight, i, kTestColours[i]));
  }
  const Y4mFile y4m = parse_y4m(read_file(file), kWidth, kHeight);
  ASSERT_EQ(y4m.frames.size(), kTestColours.size());
  const size_t luma = size_t(kWidth) * kHeight, chroma = luma / 4;
  for (size_t i = 0; i < kTestColours.size(); ++i) {
    const auto expected = bt601_limited_yuv(kTestColours[i]);
    const auto& f = y4m.frames[i];
    // +-1 code value: 8-bit integer coefficients with a truncating shift (as libyuv) stay within
    // 0.98 of the exact formula over the whole RGB cube.
    for (size_t p = 0; p < luma; ++p) ASSERT_NEAR(f[p], expected[0], 1.0) << "frame " << i << " Y " << p;
    for (size_t p = 0; p < chroma; ++p) {
      ASSERT_NEAR(f[luma + p], expected[1], 1.0) << "frame " << i << " U " << p;
      ASSERT_NEAR(f[luma + chroma + p], expected[2], 1.0) << "frame " << i << " V " << p;
    }
  }
}

TEST(Y4mSink, HonoursTheStrideAndLeavesOutAnOddLastRowAndColumn) {
  const fs::path file = scratch_dir("y4m-stride") / "video.y4m";
  // 7x5 pixels with 4 padding bytes per row; row pairs share a colour so each chroma sample
  // covers one colour only. The odd last row and column are left out: the video is 6x4.
  const std::array<Rgb, 3> row_pair_colour = {Rgb{250, 20, 20}, Rgb{20, 20, 250}, Rgb{0, 0, 0}};
  const FrameContext ctx =
      context_with_output(7, 5, 0, [&](int x, int y) { return x == 6 ? Rgb{0, 255, 0} : row_pair_colour[y / 2]; },
                          7 * 3 + 4);
  {
    Y4mSink sink(Y4mSinkConfig{true, file});
    sink.consume(ctx);
  }
  const Y4mFile y4m = parse_y4m(read_file(file), 6, 4);
  EXPECT_EQ(y4m.header, "YUV4MPEG2 W6 H4 F25:1 Ip A1:1 C420jpeg");
  ASSERT_EQ(y4m.frames.size(), 1u);
  EXPECT_EQ(y4m.torn_tail_bytes, 0u);
  const auto& f = y4m.frames[0];
  for (int y = 0; y < 4; ++y) {
    const auto expected = bt601_limited_yuv(row_pair_colour[size_t(y / 2)]);
    for (int x = 0; x < 6; ++x) EXPECT_NEAR(f[size_t(y * 6 + x)], expected[0], 1.0) << x << "," << y;
    for (int x = 0; x < 3; ++x) {
      EXPECT_NEAR(f[24 + size_t(y / 2 * 3 + x)], expected[1], 1.0) << "U " << x << "," << y / 2;
      EXPECT_NEAR(f[30 + size_t(y / 2 * 3 + x)], expected[2], 1.0) << "V " << x << "," << y / 2;
    }
  }
}

TEST(Y4mSink, AFrameOfAnotherSizeIsLoggedAndSkipped) {
  const fs::path file = scratch_dir("y4m-size-change") / "video.y4m";
  Y4mSink sink(Y4mSinkConfig{true, file});
  sink.consume(uniform_context(8, 8, 0, {10, 20, 30}));
  testing::internal::CaptureStderr();
  sink.consume(uniform_context(16, 8, 1, {10, 20, 30}));
  const std::string log = testing::internal::GetCapturedStderr();
  sink.consume(uniform_context(8, 8, 2, {10, 20, 30}));
  sink.flush();
  EXPECT_EQ(sink.frames_written(), 2u);
  EXPECT_NE(log.find(file.string()), std::string::npos) << log;
  EXPECT_NE(log.find("16x8"), std::string::npos) << log;
  const Y4mFile y4m = parse_y4m(read_file(file), 8, 8);
  EXPECT_EQ(y4m.frames.size(), 2u);
  EXPECT_TRUE(y4m.markers_ok);
  EXPECT_EQ(y4m.torn_tail_bytes, 0u);
}

TEST(Y4mSink, WriteFailureIsLoggedOnceAndLaterFramesDoNotCrash) {
  Y4mSink sink(Y4mSinkConfig{true, "/dev/full"});
  testing::internal::CaptureStderr();
  for (uint64_t i = 0; i < 4; ++i) sink.consume(uniform_context(64, 48, i, {1, 2, 3}));  // noexcept: a throw aborts
  sink.flush();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_EQ(sink.frames_written(), 0u);
  EXPECT_NE(log.find("/dev/full"), std::string::npos) << log;
  EXPECT_EQ(log.find("/dev/full", log.find("/dev/full") + 1), std::string::npos) << "logged more than once: " << log;
}

// A disk that fills up in the middle of a frame and has room again later: what was written must
// stay a valid stream (every complete frame where the format puts it, with its own pixels).
TEST(Y4mSink, AFrameCutOffByAFullDiskDoesNotMisalignTheFramesAfterIt) {
  const fs::path file = scratch_dir("y4m-torn") / "video.y4m";
  constexpr int kWidth = 64, kHeight = 48;
  const size_t frame_bytes = 6 + kWidth * kHeight * 3 / 2;
  const std::string header = "YUV4MPEG2 W64 H48 F25:1 Ip A1:1 C420jpeg\n";

  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &saved), 0);
  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);  // writes past the limit fail with EFBIG instead
  {
    Y4mSink sink(Y4mSinkConfig{true, file});
    rlimit limited = saved;
    limited.rlim_cur = header.size() + frame_bytes + frame_bytes / 2;  // room for one and a half frames
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
    testing::internal::CaptureStderr();
    for (uint64_t i = 0; i < 3; ++i) {
      sink.consume(uniform_context(kWidth, kHeight, i, kTestColours[i]));
      sink.flush();
    }
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &saved), 0);  // room again
    for (uint64_t i = 3; i < 5; ++i) sink.consume(uniform_context(kWidth, kHeight, i, kTestColours[i]));
    sink.flush();
    const std::string log = testing::internal::GetCapturedStderr();
    EXPECT_NE(log.find(file.string()), std::string::npos) << log;
  }
  setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, previous_handler);

  const Y4mFile y4m = parse_y4m(read_file(file), kWidth, kHeight);
  EXPECT_EQ(y4m.header + "\n", header);
  EXPECT_TRUE(y4m.markers_ok);
  ASSERT_GE(y4m.frames.size(), 1u);
  // Each complete frame holds the colour of one consumed frame, in order, none of them torn.
  size_t next_colour = 0;
  for (size_t k = 0; k < y4m.frames.size(); ++k) {
    bool found = false;
    for (; next_colour < 5 && !found; ++next_colour) {
      const auto expected = bt601_limited_yuv(kTestColours[next_colour]);
      found = std::abs(y4m.frames[k][0] - expected[0]) <= 1 &&
              std::abs(y4m.frames[k][y4m.frames[k].size() - 1] - expected[2]) <= 1;
      if (found) {
        for (size_t p = 0; p < size_t(kWidth * kHeight); ++p)
          ASSERT_NEAR(y4m.frames[k][p], expected[0], 1.0) << "frame " << k << " is torn at byte " << p;
      }
    }
    EXPECT_TRUE(found) << "complete frame " << k << " holds no consumed frame's pixels";
  }
  if (!have_ffprobe()) GTEST_SKIP() << "ffprobe not installed; checked with our own parser only";
  EXPECT_EQ(ffprobe_stream(file)["nb_read_frames"], std::to_string(y4m.frames.size()));
}

// ---------------------------------------------------------------------------------------------
// PNG

TEST(PngSink, WritesEveryNthFrameThatOpenCvReadsBackEqualToTheRgbInput) {
  const fs::path dir = scratch_dir("png") / "frames";  // created by the sink
  constexpr int kWidth = 13, kHeight = 7;
  // Red, green and blue all differ and vary differently, so swapped channels cannot pass.
  auto pattern = [](uint64_t index) {
    return [index](int x, int y) { return Rgb{uint8_t(x * 19 + index), uint8_t(y * 31), uint8_t(255 - x * 7 - y)}; };
  };
  PngSink sink(PngSinkConfig{true, dir, 2});
  for (uint64_t i = 0; i < 5; ++i) sink.consume(context_with_output(kWidth, kHeight, i, pattern(i), kWidth * 3 + 5));
  FrameContext nothing_composed;
  nothing_composed.input_index = 6;
  sink.consume(nothing_composed);
  EXPECT_EQ(sink.failures(), 0u);

  for (uint64_t i = 0; i < 7; ++i) {
    const fs::path file = dir / fmt::format("frame_{:06d}.png", i);
    EXPECT_EQ(PngSink::file_name(dir, i), file);
    if (i % 2 == 1 || i > 4) {
      EXPECT_FALSE(fs::exists(file)) << file;
      continue;
    }
    const cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << file;
    ASSERT_EQ(image.type(), CV_8UC3);
    ASSERT_EQ(image.cols, kWidth);
    ASSERT_EQ(image.rows, kHeight);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const Rgb want = pattern(i)(x, y);
        const cv::Vec3b got = image.at<cv::Vec3b>(y, x);  // OpenCV stores B, G, R
        ASSERT_EQ(got[2], want.r) << file << " " << x << "," << y;
        ASSERT_EQ(got[1], want.g) << file << " " << x << "," << y;
        ASSERT_EQ(got[0], want.b) << file << " " << x << "," << y;
      }
  }
}

TEST(PngSink, WriteFailureIsCountedNotThrown) {
  const fs::path dir = scratch_dir("png-gone") / "frames";
  PngSink sink(PngSinkConfig{true, dir, 1});
  fs::remove_all(dir);  // the directory disappears under the running sink
  testing::internal::CaptureStderr();
  for (uint64_t i = 0; i < 3; ++i) sink.consume(uniform_context(4, 4, i, {9, 9, 9}));
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_EQ(sink.failures(), 3u);
  EXPECT_NE(log.find((dir / "frame_000000.png").string()), std::string::npos) << log;
}

// ---------------------------------------------------------------------------------------------
// Results

std::vector<nlohmann::json> read_json_lines(const fs::path& file) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(read_file(file));
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

TEST(ResultsSink, WritesOneJsonLinePerFrameWithPoseAnchorPixelTimingsAndSkips) {
  const fs::path file = scratch_dir("results") / "sub" / "results.jsonl";
  auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(500, 510, 319.5, 239.5, 640, 480));
  const Vec3 r{0.1, -0.2, 0.3}, t{0.05, -0.03, 0.8};

  FrameContext tracked;
  tracked.input_index = 3;
  tracked.camera.meta.sequence = 41;
  tracked.camera_model = camera;
  tracked.pose.state = TrackState::Tracking;
  tracked.pose.T_cam_world = SE3::from_rt(r, t);
  tracked.record_timing("track", 2.5);
  tracked.record_timing("render", 0.125, "nothing in view");

  FrameContext lost;
  lost.input_index = 4;
  lost.camera.meta.sequence = 43;
  lost.camera_model = camera;
  lost.pose.state = TrackState::Lost;
  lost.record_timing("track", 3.0);

  FrameContext behind = tracked;  // anchor behind the camera: no pixel for it
  behind.input_index = 5;
  behind.pose.T_cam_world = SE3::from_rt(r, {0.05, -0.03, -0.8});

  ResultsSink sink(ResultsSinkConfig{true, file});
  sink.consume(tracked);
  // Lines are flushed as they are written: the first is readable before the sink is flushed.
  ASSERT_EQ(read_json_lines(file).size(), 1u);
  sink.consume(lost);
  sink.consume(behind);
  sink.flush();

  const auto lines = read_json_lines(file);
  ASSERT_EQ(lines.size(), 3u);
  const auto& j = lines[0];
  EXPECT_EQ(j.at("index"), 3);
  EXPECT_EQ(j.at("sequence"), 41);
  EXPECT_EQ(j.at("track_state"), "tracking");
  // r goes through a rotation matrix and back (Rodrigues both ways): a few ulps.
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(j.at("T_cam_world").at("r")[size_t(k)].get<double>(), r[size_t(k)], 1e-12);
    EXPECT_EQ(j.at("T_cam_world").at("t")[size_t(k)].get<double>(), t[size_t(k)]);  // printed round-trip exact
  }
  // The world origin lands at the camera-frame point t: check against the camera model and,
  // independently, the pinhole formula (1e-9 px: both are the same double arithmetic up to ulps).
  const auto expected_px = camera->project(t);
  ASSERT_TRUE(expected_px);
  ASSERT_TRUE(j.contains("anchor_px"));
  EXPECT_NEAR(j.at("anchor_px")[0].get<double>(), (*expected_px)[0], 1e-9);
  EXPECT_NEAR(j.at("anchor_px")[1].get<double>(), (*expected_px)[1], 1e-9);
  EXPECT_NEAR(j.at("anchor_px")[0].get<double>(), 500 * t[0] / t[2] + 319.5, 1e-9);
  EXPECT_NEAR(j.at("anchor_px")[1].get<double>(), 510 * t[1] / t[2] + 239.5, 1e-9);
  EXPECT_EQ(j.at("stage_ms"), (nlohmann::json{{"track", 2.5}, {"render", 0.125}}));
  EXPECT_EQ(j.at("skipped"), (nlohmann::json{{"render", "nothing in view"}}));

  EXPECT_EQ(lines[1].at("index"), 4);
  EXPECT_EQ(lines[1].at("sequence"), 43);
  EXPECT_EQ(lines[1].at("track_state"), "lost");
  EXPECT_FALSE(lines[1].contains("T_cam_world"));
  EXPECT_FALSE(lines[1].contains("anchor_px"));
  EXPECT_EQ(lines[1].at("stage_ms"), (nlohmann::json{{"track", 3.0}}));
  EXPECT_EQ(lines[1].at("skipped"), nlohmann::json::object());

  EXPECT_EQ(lines[2].at("track_state"), "tracking");
  EXPECT_TRUE(lines[2].contains("T_cam_world"));
  EXPECT_FALSE(lines[2].contains("anchor_px"));
}

TEST(ResultsSink, AStereoEyesAnchorPixelIsWhereThatEyeSeesIt) {
  // The anchor 0.5 m straight ahead on the horizon, seen from a stereo panorama's eyes 64 mm apart:
  // each eye's ray to it leaves the eye circle tangentially, so the left eye sees it at
  // f r / sqrt(D^2 - r^2) right of the centre (r = 32 mm, sin of the angle r / D) and the right eye
  // as far left, where the render stage draws it (ods_projection.h); a mono frame at the centre.
  const fs::path file = scratch_dir("results-stereo") / "results.jsonl";
  auto camera = std::make_shared<const CameraModel>(CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480));
  const double distance = 0.5, r = 0.032;
  // Camera x = world x, camera y = -world z (down), camera z = world y (ahead).
  const Mat3 R_cam_world{{{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}};
  ResultsSink sink(ResultsSinkConfig{true, file});
  for (const Eye eye : {Eye::Left, Eye::Right, Eye::Mono}) {
    FrameContext ctx;
    ctx.camera_model = camera;
    ctx.pose.state = TrackState::Tracking;
    ctx.pose.T_cam_world = SE3(R_cam_world, {0, 0, distance});
    ctx.camera.meta.eye = eye;
    ctx.camera.meta.ods.ipd_m = 2 * r;
    sink.consume(ctx);
  }
  sink.flush();
  const auto lines = read_json_lines(file);
  ASSERT_EQ(lines.size(), 3u);
  const double offset = 500 * r / std::sqrt(distance * distance - r * r);
  for (const auto& [line, expected_x] : {std::pair{0, 319.5 + offset}, std::pair{1, 319.5 - offset}, std::pair{2, 319.5}}) {
    ASSERT_TRUE(lines[size_t(line)].contains("anchor_px")) << line;
    EXPECT_NEAR(lines[size_t(line)].at("anchor_px")[0].get<double>(), expected_x, 1e-6) << "line " << line;
    EXPECT_NEAR(lines[size_t(line)].at("anchor_px")[1].get<double>(), 239.5, 1e-6) << "line " << line;
  }
}

TEST(ResultsSink, WriteFailureIsLoggedNotThrown) {
  ResultsSink sink(ResultsSinkConfig{true, "/dev/full"});
  FrameContext ctx;
  testing::internal::CaptureStderr();
  for (int i = 0; i < 3; ++i) sink.consume(ctx);
  sink.flush();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("/dev/full"), std::string::npos) << log;
}

// ---------------------------------------------------------------------------------------------
// Recording

TEST(RecordingSink, WritesARecordingThatTheReaderGivesBackExactly) {
  const fs::path dir = scratch_dir("recording-sink") / "out" / "composited";
  constexpr int kWidth = 10, kHeight = 6;
  auto camera = std::make_shared<const CameraModel>(small_camera(kWidth, kHeight));
  std::vector<FrameContext> contexts;
  for (uint64_t i = 0; i < 3; ++i) {
    FrameContext ctx = context_with_output(
        kWidth, kHeight, i, [i](int x, int y) { return Rgb{uint8_t(x + 40 * i), uint8_t(y * 9), uint8_t(x * y)}; },
        kWidth * 3 + 2);  // a padded stride must survive too
    ctx.camera = random_frame(PixelFormat::NV12, kWidth, kHeight, kWidth, i);  // every metadata field set
    ctx.camera_model = camera;
    contexts.push_back(std::move(ctx));
  }
  {
    RecordingSink sink(RecordingSinkConfig{true, dir});
    for (const auto& ctx : contexts) sink.consume(ctx);
    sink.flush();
  }
  RecordingReader reader(dir);
  EXPECT_TRUE(reader.warnings().empty());
  EXPECT_EQ(reader.info().pixel_format, PixelFormat::RGB24);
  EXPECT_EQ(reader.info().width, kWidth);
  EXPECT_EQ(reader.info().height, kHeight);
  EXPECT_EQ(reader.camera_model().lensmodel(), camera->lensmodel());
  EXPECT_EQ(reader.camera_model().intrinsics(), camera->intrinsics());
  ASSERT_EQ(reader.frame_count(), contexts.size());
  for (size_t i = 0; i < contexts.size(); ++i) {
    Frame frame;
    reader.read(i, frame);
    const FrameMetadata& want = contexts[i].camera.meta;
    EXPECT_EQ(frame.meta.sequence, want.sequence);
    EXPECT_EQ(frame.meta.exposure_start_ns, want.exposure_start_ns);
    EXPECT_EQ(frame.meta.exposure_ns, want.exposure_ns);
    EXPECT_EQ(frame.meta.readout_ns, want.readout_ns);
    EXPECT_EQ(frame.meta.frame_duration_ns, want.frame_duration_ns);
    EXPECT_EQ(frame.meta.analogue_gain, want.analogue_gain);
    EXPECT_EQ(frame.meta.digital_gain, want.digital_gain);
    EXPECT_EQ(frame.meta.raw_timestamp_ns, want.raw_timestamp_ns);
    EXPECT_EQ(frame.meta.raw_timestamp_meaning, want.raw_timestamp_meaning);
    EXPECT_EQ(frame.meta.timestamp_offset_ns, want.timestamp_offset_ns);
    ASSERT_EQ(frame.format, PixelFormat::RGB24);
    ASSERT_EQ(frame.width, kWidth);
    ASSERT_EQ(frame.height, kHeight);
    const Frame& output = contexts[i].output;
    for (int y = 0; y < kHeight; ++y)
      ASSERT_TRUE(std::equal(output.data.begin() + long(size_t(y) * output.bytes_per_line),
                             output.data.begin() + long(size_t(y) * output.bytes_per_line + kWidth * 3),
                             frame.data.begin() + long(size_t(y) * frame.bytes_per_line)))
          << "frame " << i << " row " << y;
  }
}

TEST(RecordingSink, MissingCameraModelIsLoggedAndNothingCrashes) {
  const fs::path dir = scratch_dir("recording-sink-no-model") / "composited";
  RecordingSink sink(RecordingSinkConfig{true, dir});
  testing::internal::CaptureStderr();
  for (uint64_t i = 0; i < 3; ++i) sink.consume(uniform_context(4, 4, i, {1, 1, 1}));
  sink.flush();
  const std::string log = testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find(dir.string()), std::string::npos) << log;
  EXPECT_NE(log.find("camera model"), std::string::npos) << log;
}

// ---------------------------------------------------------------------------------------------
// Output locations that cannot be created

TEST(Sinks, DirectoryThatCannotBeCreatedThrowsNamingThePathAndTheConfigKey) {
  const fs::path root = scratch_dir("blocked");
  const fs::path blocker = root / "not_a_directory";
  write_file(blocker, "a regular file where a directory should go\n");
  const fs::path below = blocker / "out";

  struct Case {
    std::string key;
    std::function<void()> make;
  };
  const std::vector<Case> cases = {
      {"sinks.png.dir", [&] { PngSink sink(PngSinkConfig{true, below / "png", 1}); }},
      {"sinks.y4m.path", [&] { Y4mSink sink(Y4mSinkConfig{true, below / "video.y4m"}); }},
      {"sinks.results.path", [&] { ResultsSink sink(ResultsSinkConfig{true, below / "results.jsonl"}); }},
      {"sinks.recording.path", [&] { RecordingSink sink(RecordingSinkConfig{true, below / "composited"}); }},
  };
  for (const auto& c : cases) {
    const std::string message = error_message<std::runtime_error>(c.make);
    EXPECT_NE(message.find(below.string()), std::string::npos) << c.key << ": " << message;
    EXPECT_NE(message.find(c.key), std::string::npos) << message;
  }
}

TEST(Sinks, FileThatCannotBeOpenedThrowsNamingThePathAndTheConfigKey) {
  const fs::path dir = scratch_dir("is-a-directory");  // a directory where the file should go
  EXPECT_NE(error_message<std::runtime_error>([&] { Y4mSink sink(Y4mSinkConfig{true, dir}); }).find(
                fmt::format("{} (config sinks.y4m.path)", dir.string())),
            std::string::npos);
  EXPECT_NE(error_message<std::runtime_error>([&] { ResultsSink sink(ResultsSinkConfig{true, dir}); }).find(
                fmt::format("{} (config sinks.results.path)", dir.string())),
            std::string::npos);
}

}  // namespace
}  // namespace arpipe
