// The V4L2 output sink through the stand-in's loopback pair (linked into this test): what the sink
// writes to the output node is read back from the capture node, frame by frame, with raw ioctls.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "capture/sinks/v4l2/v4l2_output_sink.h"
#include "core/image/pixel_convert.h"
#include "standin_fixture.h"

namespace arpipe {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLoopOutput = "/dev/video-arpipe-loop-out";
constexpr const char* kLoopCapture = "/dev/video-arpipe-loop-cap";
constexpr int64_t kFrameDurationNs = 33'333'333;

// Loads a stand-in config with one [[loopback]] (and `extra` inside it); unloads when destroyed.
class Loopback {
 public:
  Loopback(const fs::path& dir, const std::string& extra = "") {
    const fs::path config = dir / "standin.toml";
    std::ofstream(config) << "[[loopback]]\noutput = \"" << kLoopOutput << "\"\ncapture = \"" << kLoopCapture
                          << "\"\nspool = \"spool\"\n" << extra << "\n";
    char error[512] = {};
    EXPECT_EQ(arpipe_v4l2_standin_load(config.c_str(), error, sizeof error), 0) << error;
  }
  ~Loopback() { arpipe_v4l2_standin_unload(); }
  static struct arpipe_v4l2_standin_stats stats(const char* path) {
    struct arpipe_v4l2_standin_stats s{};
    arpipe_v4l2_standin_stats(path, &s);
    return s;
  }
};

// A composited frame as the pipeline hands it over: RGB24 with padded rows (the sink must not
// copy the padding), a picture of its own, and exposure times 33 ms apart.
FrameContext composite(int index, int width, int height) {
  FrameContext ctx;
  ctx.input_index = uint64_t(index);
  Frame& f = ctx.output;
  f.format = PixelFormat::RGB24;
  f.width = width;
  f.height = height;
  f.bytes_per_line = size_t(width) * 3 + 5;
  f.data.resize(f.bytes_per_line * size_t(height));
  std::mt19937 random(uint32_t(index) + 1);
  for (auto& b : f.data) b = uint8_t(random());
  f.meta.sequence = uint64_t(index);
  f.meta.exposure_start_ns = 5'000'123'456 + int64_t(index) * kFrameDurationNs;
  f.meta.exposure_ns = 4'000'000;
  f.meta.frame_duration_ns = kFrameDurationNs;
  return ctx;
}

// The frame's pixels without row padding.
std::vector<uint8_t> packed_rgb(const Frame& f) {
  std::vector<uint8_t> out;
  for (int y = 0; y < f.height; ++y) {
    const uint8_t* row = f.data.data() + size_t(y) * f.bytes_per_line;
    out.insert(out.end(), row, row + size_t(f.width) * 3);
  }
  return out;
}

struct ReadFrame {
  std::vector<uint8_t> bytes;
  int64_t timestamp_us = 0;
  uint32_t sequence = 0;
  uint32_t flags = 0;
};

// A V4L2 reader of the capture node, as ffmpeg's v4l2 input does it: G_FMT, REQBUFS, mmap, QBUF
// all, STREAMON, then poll + DQBUF + QBUF.
class CaptureReader {
 public:
  CaptureReader() {
    fd_ = ::open(kLoopCapture, O_RDWR | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error(std::string("open: ") + std::strerror(errno));
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (::ioctl(fd_, VIDIOC_G_FMT, &format) != 0) throw std::runtime_error(std::string("G_FMT: ") + std::strerror(errno));
    v4l2_requestbuffers r{};
    r.count = 4;
    r.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    r.memory = V4L2_MEMORY_MMAP;
    if (::ioctl(fd_, VIDIOC_REQBUFS, &r) != 0) throw std::runtime_error("REQBUFS");
    for (uint32_t i = 0; i < r.count; ++i) {
      v4l2_buffer b{};
      b.index = i;
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      if (::ioctl(fd_, VIDIOC_QUERYBUF, &b) != 0) throw std::runtime_error("QUERYBUF");
      void* p = ::mmap(nullptr, b.length, PROT_READ, MAP_SHARED, fd_, b.m.offset);
      if (p == MAP_FAILED) throw std::runtime_error("mmap");
      maps_.push_back({static_cast<uint8_t*>(p), b.length});
      if (::ioctl(fd_, VIDIOC_QBUF, &b) != 0) throw std::runtime_error("QBUF");
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (::ioctl(fd_, VIDIOC_STREAMON, &type) != 0) throw std::runtime_error("STREAMON");
  }
  ~CaptureReader() {
    for (const auto& [p, n] : maps_) ::munmap(p, n);
    if (fd_ >= 0) ::close(fd_);
  }
  // The next frame, waiting at most timeout_ms; nullopt when none came.
  std::optional<ReadFrame> next(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) != 1 || !(p.revents & POLLIN)) return std::nullopt;
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (::ioctl(fd_, VIDIOC_DQBUF, &b) != 0) return std::nullopt;
    ReadFrame f;
    f.bytes.assign(maps_[b.index].first, maps_[b.index].first + std::min<size_t>(b.bytesused, maps_[b.index].second));
    f.timestamp_us = int64_t(b.timestamp.tv_sec) * 1'000'000 + b.timestamp.tv_usec;
    f.sequence = b.sequence;
    f.flags = b.flags;
    EXPECT_EQ(::ioctl(fd_, VIDIOC_QBUF, &b), 0);
    return f;
  }
  v4l2_format format{};

 private:
  int fd_ = -1;
  std::vector<std::pair<uint8_t*, size_t>> maps_;
};

V4l2SinkConfig sink_config(V4l2OutputFormat format) {
  V4l2SinkConfig c;
  c.enabled = true;
  c.device = kLoopOutput;
  c.format = format;
  return c;
}

TEST(V4l2OutputSink, Rgb24FramesArriveByteExactInOrderWithTheirExposureStarts) {
  const auto dir = test::v4l2_scratch("sink-rgb24");
  Loopback loopback(dir);
  constexpr int kFrames = 12;
  std::vector<FrameContext> frames;
  for (int i = 0; i < kFrames; ++i) frames.push_back(composite(i, 64, 48));
  {
    V4l2OutputSink sink(sink_config(V4l2OutputFormat::Rgb24));
    for (const auto& ctx : frames) sink.consume(ctx);
    EXPECT_EQ(sink.frames_written(), uint64_t(kFrames));
    EXPECT_EQ(sink.frames_dropped(), 0u);
    EXPECT_EQ(sink.failures(), 0u);
  }
  EXPECT_EQ(Loopback::stats(kLoopOutput).frames_written, uint64_t(kFrames));

  CaptureReader reader;
  EXPECT_EQ(reader.format.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_RGB24));
  EXPECT_EQ(reader.format.fmt.pix.width, 64u);
  EXPECT_EQ(reader.format.fmt.pix.height, 48u);
  for (int i = 0; i < kFrames; ++i) {
    const auto got = reader.next(2000);
    ASSERT_TRUE(got) << "frame " << i << " did not arrive within 2 s";
    EXPECT_EQ(got->bytes, packed_rgb(frames[size_t(i)].output)) << "frame " << i;
    // A timeval: the exposure start to the microsecond, truncated.
    EXPECT_EQ(got->timestamp_us, frames[size_t(i)].output.meta.exposure_start_ns / 1000) << "frame " << i;
    EXPECT_EQ(got->sequence, uint32_t(i));
    EXPECT_EQ(got->flags & V4L2_BUF_FLAG_TIMESTAMP_MASK, uint32_t(V4L2_BUF_FLAG_TIMESTAMP_COPY));
  }
  EXPECT_FALSE(reader.next(100)) << "more frames than were written";
}

TEST(V4l2OutputSink, YuyvFramesAreTheConvertersOutput) {
  const auto dir = test::v4l2_scratch("sink-yuyv");
  Loopback loopback(dir);
  constexpr int kFrames = 6;
  std::vector<FrameContext> frames;
  // An odd width: 4:2:2 pairs columns, so the stream is 64 wide and the last column is left out.
  for (int i = 0; i < kFrames; ++i) frames.push_back(composite(i, 65, 48));
  {
    V4l2OutputSink sink(sink_config(V4l2OutputFormat::Yuyv));
    for (const auto& ctx : frames) sink.consume(ctx);
    EXPECT_EQ(sink.frames_written(), uint64_t(kFrames));
  }
  CaptureReader reader;
  EXPECT_EQ(reader.format.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_YUYV));
  EXPECT_EQ(reader.format.fmt.pix.width, 64u);
  for (int i = 0; i < kFrames; ++i) {
    const auto got = reader.next(2000);
    ASSERT_TRUE(got) << "frame " << i;
    const Frame& f = frames[size_t(i)].output;
    std::vector<uint8_t> expected(64 * 2 * 48);
    rgb24_to_yuyv(f.data.data(), f.bytes_per_line, 64, 48, expected.data(), 64 * 2);
    EXPECT_EQ(got->bytes, expected) << "frame " << i;
    EXPECT_EQ(got->timestamp_us, f.meta.exposure_start_ns / 1000);
  }
  EXPECT_FALSE(reader.next(100));
}

// rgb24_to_yuyv (strided, into a buffer) gives the bytes of from_rgb24(..., YUYV), BT.601 limited
// range: black is Y 16, white Y 235, greys have neutral chroma (128).
TEST(V4l2OutputSink, YuyvConverterIsBt601LimitedRangeLikeTheRest) {
  std::vector<uint8_t> rgb(16 * 4 * 3);
  std::mt19937 random(7);
  for (auto& b : rgb) b = uint8_t(random());
  const Frame reference = from_rgb24(rgb.data(), 16, 4, PixelFormat::YUYV);
  std::vector<uint8_t> out(16 * 2 * 4);
  rgb24_to_yuyv(rgb.data(), 16 * 3, 16, 4, out.data(), 16 * 2);
  EXPECT_EQ(out, reference.data);

  const uint8_t black_white[] = {0, 0, 0, 255, 255, 255};
  uint8_t yuyv[4];
  rgb24_to_yuyv(black_white, 6, 2, 1, yuyv, 4);
  EXPECT_EQ(yuyv[0], 16);
  EXPECT_EQ(yuyv[2], 235);
  EXPECT_EQ(yuyv[1], 128);
  EXPECT_EQ(yuyv[3], 128);
}

// The output node holds its buffers for 1.5 s from frame 2 on (a reader that stopped): consume()
// never waits longer than its bound (66 ms at 30 fps; asserted below 0.5 s), drops and counts the
// frames for which no buffer came back, and the frames it did write arrive, in order, exact.
TEST(V4l2OutputSink, StuckDeviceDropsAndCountsInsteadOfBlocking) {
  const auto dir = test::v4l2_scratch("sink-stall");
  Loopback loopback(dir, "[[loopback.fault]]\nframe = 2\nkind = \"stall\"\nduration_ms = 1500\n");
  EXPECT_EQ(V4l2OutputSink::dequeue_wait_ns(kFrameDurationNs), 2 * kFrameDurationNs);
  constexpr int kFrames = 10;
  std::vector<FrameContext> frames;
  for (int i = 0; i < kFrames; ++i) frames.push_back(composite(i, 32, 16));
  uint64_t written = 0, dropped = 0;
  {
    V4l2OutputSink sink(sink_config(V4l2OutputFormat::Rgb24));
    const auto first = std::chrono::steady_clock::now();
    for (const auto& ctx : frames) {
      const auto start = std::chrono::steady_clock::now();
      sink.consume(ctx);
      EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(500)) << "frame " << ctx.input_index;
    }
    written = sink.frames_written();
    dropped = sink.frames_dropped();
    EXPECT_EQ(sink.failures(), 0u);
    // The stall ends; the held frames are taken before the sink's STREAMOFF (which would drop them).
    std::this_thread::sleep_until(first + std::chrono::milliseconds(1700));
  }
  EXPECT_GT(dropped, 0u);
  EXPECT_EQ(written + dropped, uint64_t(kFrames));
  EXPECT_EQ(Loopback::stats(kLoopOutput).frames_written, written);
  CaptureReader reader;
  std::vector<ReadFrame> got;
  while (auto f = reader.next(300)) got.push_back(std::move(*f));
  ASSERT_EQ(got.size(), written);
  // Every frame read is one of the frames, whole, and they come in order.
  size_t next = 0;
  for (const ReadFrame& f : got) {
    while (next < frames.size() && frames[next].output.meta.exposure_start_ns / 1000 != f.timestamp_us) ++next;
    ASSERT_LT(next, frames.size()) << "a frame read back is none of the frames written, or out of order";
    EXPECT_EQ(f.bytes, packed_rgb(frames[next].output));
    ++next;
  }
}

TEST(V4l2OutputSink, RefusesWhatIsNotAnOutputDeviceNamingTheKey) {
  const auto dir = test::v4l2_scratch("sink-refuse");
  Loopback loopback(dir);
  const auto message = [](const V4l2SinkConfig& c) {
    try {
      V4l2OutputSink sink(c);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto config = sink_config(V4l2OutputFormat::Yuyv);
  config.device = "/dev/video-arpipe-nothing-here";
  EXPECT_NE(message(config).find("sinks.v4l2.device = \"/dev/video-arpipe-nothing-here\": cannot open it"),
            std::string::npos)
      << message(config);
  config.device = kLoopCapture;
  EXPECT_NE(message(config).find("is not a streaming video output device"), std::string::npos) << message(config);
}

// A reload: the new sink is made while the old one still streams (the pipeline closes the old one
// at the frame boundary, then hands frames to the new one); the reader gets both runs' frames, in order.
TEST(V4l2OutputSink, ASinkMadeWhileAnotherStreamsTakesOverAfterIt) {
  const auto dir = test::v4l2_scratch("sink-reload");
  Loopback loopback(dir);
  std::vector<FrameContext> frames;
  for (int i = 0; i < 6; ++i) frames.push_back(composite(i, 32, 16));
  auto old_sink = std::make_unique<V4l2OutputSink>(sink_config(V4l2OutputFormat::Rgb24));
  for (int i = 0; i < 3; ++i) old_sink->consume(frames[size_t(i)]);
  V4l2OutputSink new_sink(sink_config(V4l2OutputFormat::Rgb24));
  old_sink.reset();
  for (int i = 3; i < 6; ++i) new_sink.consume(frames[size_t(i)]);
  EXPECT_EQ(new_sink.frames_written(), 3u);
  EXPECT_EQ(new_sink.failures(), 0u);
  CaptureReader reader;
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto got = reader.next(2000);
    ASSERT_TRUE(got) << "frame " << i;
    EXPECT_EQ(got->bytes, packed_rgb(frames[i].output)) << "frame " << i;
    EXPECT_EQ(got->timestamp_us, frames[i].output.meta.exposure_start_ns / 1000);
  }
  EXPECT_FALSE(reader.next(100));
}

// A driver that answers another format than asked (this output node takes YUYV only) is refused
// by name at the first frame: nothing is written, every frame is counted as a failure.
TEST(V4l2OutputSink, RefusesAFormatTheDriverChanges) {
  const auto dir = test::v4l2_scratch("sink-refuse-format");
  Loopback loopback(dir, "formats = [\"YUYV\"]\n");
  V4l2OutputSink sink(sink_config(V4l2OutputFormat::Rgb24));
  for (int i = 0; i < 3; ++i) sink.consume(composite(i, 32, 16));
  EXPECT_EQ(sink.frames_written(), 0u);
  EXPECT_EQ(sink.failures(), 3u);
  EXPECT_EQ(Loopback::stats(kLoopOutput).frames_written, 0u);
}

}  // namespace
}  // namespace arpipe
