// The stand-in's [[loopback]] pair: config errors with their place, the output node's format
// negotiation, frames written to the output read back from the capture node (raw ioctls), and a
// damaged spool file served as an error buffer rather than trusted.
#include <fstream>

#include "standin_fixture.h"

namespace arpipe::standin_test {
namespace {

constexpr const char* kOut = "/dev/video-loop-out";
constexpr const char* kCap = "/dev/video-loop-cap";

class LoopbackTest : public StandinTest {
 protected:
  std::string loopback_table(const std::string& extra = "") const {
    return std::string("[[loopback]]\noutput = \"") + kOut + "\"\ncapture = \"" + kCap + "\"\nspool = \"spool\"\n" + extra;
  }
  std::string load_error(const std::string& text) {
    char error[512] = "";
    EXPECT_EQ(arpipe_v4l2_standin_load(write_config(text).c_str(), error, sizeof error), -1) << text;
    return error;
  }
  void load_loopback(const std::string& extra = "") {
    char error[512] = "";
    ASSERT_EQ(arpipe_v4l2_standin_load(write_config(loopback_table(extra)).c_str(), error, sizeof error), 0) << error;
  }

  // Sets the output's format, allocates `count` buffers, maps them, starts streaming.
  std::vector<uint8_t*> start_output(int fd, uint32_t fourcc, uint32_t width, uint32_t height, uint32_t count) {
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    f.fmt.pix.width = width;
    f.fmt.pix.height = height;
    f.fmt.pix.pixelformat = fourcc;
    EXPECT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), 0) << strerror(errno);
    v4l2_requestbuffers r{};
    r.count = count;
    r.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    r.memory = V4L2_MEMORY_MMAP;
    EXPECT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0) << strerror(errno);
    std::vector<uint8_t*> maps;
    for (uint32_t i = 0; i < r.count; ++i) {
      v4l2_buffer b{};
      b.index = i;
      b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
      b.memory = V4L2_MEMORY_MMAP;
      EXPECT_EQ(ioctl(fd, VIDIOC_QUERYBUF, &b), 0);
      void* p = mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, b.m.offset);
      EXPECT_NE(p, MAP_FAILED) << strerror(errno);
      maps_.push_back({p, b.length});
      maps.push_back(static_cast<uint8_t*>(p));
    }
    int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    EXPECT_EQ(ioctl(fd, VIDIOC_STREAMON, &type), 0) << strerror(errno);
    return maps;
  }
  static int write_frame(int fd, uint32_t index, uint32_t bytes, int64_t timestamp_us) {
    v4l2_buffer b{};
    b.index = index;
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    b.bytesused = bytes;
    b.flags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
    b.timestamp.tv_sec = timestamp_us / 1000000;
    b.timestamp.tv_usec = timestamp_us % 1000000;
    if (ioctl(fd, VIDIOC_QBUF, &b) != 0) return -1;
    b = {};
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    return ioctl(fd, VIDIOC_DQBUF, &b);  // done at once: the loopback never waits for a reader
  }
};

TEST_F(LoopbackTest, ConfigErrorsNameTheirPlace) {
  EXPECT_NE(load_error("[[loopback]]\ncapture = \"/dev/b\"\nspool = \"s\"\n")
                .find("standin.toml:1:1: loopback[0].output: expected an absolute path, found nothing"),
            std::string::npos);
  EXPECT_NE(load_error("[[loopback]]\noutput = \"/dev/a\"\ncapture = \"/dev/./a\"\nspool = \"s\"\n")
                .find("standin.toml:3:11: loopback[0].capture: expected a path other than the output's, found \"/dev/a\""),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("formats = [\"YUYV\", \"MJPG\"]\n")).find("standin.toml:5:11: loopback[0].formats: expected an array of raw pixel formats"),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("formats = [\"RGB24\", \"RGB24\"]\n")).find("standin.toml:5:11: loopback[0].formats: expected each format once"),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("max_width = 1\n")).find("standin.toml:5:13: loopback[0].max_width: expected"),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("max_spool_mib = 0\n")).find("standin.toml:5:17: loopback[0].max_spool_mib: expected"),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("[[loopback.fault]]\nframe = 3\nkind = \"drop\"\n"))
                .find("standin.toml:7:8: loopback[0].fault[0].kind: expected \"stall\", found \"drop\""),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("[[loopback.fault]]\nframe = 3\nkind = \"stall\"\n"))
                .find("standin.toml:5:1: loopback[0].fault[0].duration_ms: expected"),
            std::string::npos);
  EXPECT_NE(load_error(loopback_table("looped = true\n")).find("standin.toml:5:1: loopback[0].looped: unknown key"),
            std::string::npos);
  // One path, one node: a [[device]] path cannot also be a loopback's.
  const std::string e = load_error("[[device]]\npath = \"" + std::string(kOut) + "\"\nrecording = \"" + kDefaultCapture.string() +
                                   "\"\n" + loopback_table());
  EXPECT_NE(e.find("standin.toml:5:10: loopback[0].output: expected a path no earlier [[device]] or [[loopback]] serves"),
            std::string::npos)
      << e;
  EXPECT_NE(load_error("x = 1\n").find("standin.toml:1:1: device: expected at least one [[device]] or [[loopback]] table"),
            std::string::npos);
}

TEST_F(LoopbackTest, OutputNodeAdjustsFormatsLikeADriver) {
  load_loopback("formats = [\"YUYV\", \"RGB24\"]\nmax_width = 1280\nmax_height = 720\n");
  const int fd = open_device(O_RDWR | O_NONBLOCK, kOut);
  ASSERT_GE(fd, 0);
  v4l2_capability cap{};
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERYCAP, &cap), 0);
  EXPECT_EQ(cap.device_caps, uint32_t(V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT));
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  f.fmt.pix.width = 641;  // YUYV pairs columns
  f.fmt.pix.height = 5000;
  f.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  ASSERT_EQ(ioctl(fd, VIDIOC_TRY_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.width, 640u);
  EXPECT_EQ(f.fmt.pix.height, 720u);
  EXPECT_EQ(f.fmt.pix.bytesperline, 1280u);
  EXPECT_EQ(f.fmt.pix.sizeimage, 1280u * 720u);
  f.fmt.pix.pixelformat = V4L2_PIX_FMT_MJPEG;  // not offered: the first one instead
  ASSERT_EQ(ioctl(fd, VIDIOC_TRY_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_YUYV));
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(ioctl(fd, VIDIOC_TRY_FMT, &f), -1);
  EXPECT_EQ(errno, EINVAL);
}

TEST_F(LoopbackTest, CaptureNodeHasNoFormatUntilAWriterSetsOne) {
  load_loopback();
  const int cap_fd = open_device(O_RDWR | O_NONBLOCK, kCap);
  ASSERT_GE(cap_fd, 0);
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(ioctl(cap_fd, VIDIOC_G_FMT, &f), -1);
  EXPECT_EQ(errno, EINVAL);
  const int out_fd = open_device(O_RDWR | O_NONBLOCK, kOut);
  ASSERT_GE(out_fd, 0);
  f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  f.fmt.pix.width = 32;
  f.fmt.pix.height = 8;
  f.fmt.pix.pixelformat = V4L2_PIX_FMT_RGB24;
  ASSERT_EQ(ioctl(out_fd, VIDIOC_S_FMT, &f), 0);
  f = {};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  f.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;  // any request gets the writer's format
  ASSERT_EQ(ioctl(cap_fd, VIDIOC_S_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_RGB24));
  EXPECT_EQ(f.fmt.pix.width, 32u);
  EXPECT_EQ(f.fmt.pix.height, 8u);
}

// Frames go through in order with their bytes, sizes and timestamps; a frame file damaged in the
// spool (its size no longer matches its header) is served as an error buffer, named on stderr,
// and the frames after it still come.
TEST_F(LoopbackTest, FramesPassInOrderAndADamagedSpoolFileIsAnErrorBuffer) {
  load_loopback();
  const int out_fd = open_device(O_RDWR | O_NONBLOCK, kOut);
  ASSERT_GE(out_fd, 0);
  const auto out = start_output(out_fd, V4L2_PIX_FMT_RGB24, 16, 4, 2);
  ASSERT_EQ(out.size(), 2u);
  for (uint32_t i = 0; i < 4; ++i) {
    std::memset(out[i % 2], int(10 + i), 16 * 4 * 3);
    ASSERT_EQ(write_frame(out_fd, i % 2, 16 * 4 * 3, 7000000 + i * 40000), 0) << strerror(errno);
  }
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kOut, &stats), 0);
  EXPECT_EQ(stats.frames_written, 4u);
  // bytesused above the buffer is refused.
  v4l2_buffer big{};
  big.index = 0;
  big.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  big.memory = V4L2_MEMORY_MMAP;
  big.bytesused = 1u << 20;
  EXPECT_EQ(ioctl(out_fd, VIDIOC_QBUF, &big), -1);
  EXPECT_EQ(errno, EINVAL);

  std::filesystem::resize_file(dir_ / "spool" / "0000000001.frame", 64 + 10);  // cut short
  const int cap_fd = open_device(O_RDWR | O_NONBLOCK, kCap);
  ASSERT_GE(cap_fd, 0);
  const auto in = start(cap_fd, 2);
  for (uint32_t i = 0; i < 4; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(cap_fd, b, 2000)) << "frame " << i;
    EXPECT_EQ(b.sequence, i);
    if (i == 1) {
      EXPECT_TRUE(b.flags & V4L2_BUF_FLAG_ERROR);
      EXPECT_EQ(b.bytesused, 0u);
    } else {
      EXPECT_FALSE(b.flags & V4L2_BUF_FLAG_ERROR) << "frame " << i;
      EXPECT_EQ(int64_t(b.timestamp.tv_sec) * 1000000 + b.timestamp.tv_usec, int64_t(7000000 + i * 40000));
      ASSERT_EQ(b.bytesused, 16u * 4 * 3);
      EXPECT_EQ(in[b.index][0], uint8_t(10 + i));
      EXPECT_EQ(in[b.index][16 * 4 * 3 - 1], uint8_t(10 + i));
    }
    ASSERT_EQ(qbuf(cap_fd, b.index), 0);
  }
  v4l2_buffer none{};
  EXPECT_FALSE(next_buffer(cap_fd, none, 50)) << "only four frames were written";
  ASSERT_EQ(arpipe_v4l2_standin_stats(kCap, &stats), 0);
  EXPECT_EQ(stats.frames_delivered, 4u);
  EXPECT_EQ(stats.error_buffers, 1u);
}

// A spool past max_spool_mib takes no more frames: their buffers come back with
// V4L2_BUF_FLAG_ERROR and are counted; the writer never waits.
TEST_F(LoopbackTest, AFullSpoolRefusesFramesWithErrorBuffers) {
  load_loopback("max_spool_mib = 1\n");
  const int fd = open_device(O_RDWR | O_NONBLOCK, kOut);
  ASSERT_GE(fd, 0);
  start_output(fd, V4L2_PIX_FMT_RGB24, 640, 480, 2);  // 921600 bytes a frame: one fits in 1 MiB
  for (uint32_t i = 0; i < 3; ++i) {
    v4l2_buffer b{};
    b.index = i % 2;
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    b.bytesused = 640 * 480 * 3;
    ASSERT_EQ(ioctl(fd, VIDIOC_QBUF, &b), 0) << strerror(errno);
    b = {};
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    ASSERT_EQ(ioctl(fd, VIDIOC_DQBUF, &b), 0) << strerror(errno);
    EXPECT_EQ((b.flags & V4L2_BUF_FLAG_ERROR) != 0, i > 0) << "frame " << i;
  }
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kOut, &stats), 0);
  EXPECT_EQ(stats.frames_written, 1u);
  EXPECT_EQ(stats.error_buffers, 2u);
}

// A damaged `format` file is no format: the capture node answers EINVAL and says why on stderr.
TEST_F(LoopbackTest, ADamagedFormatFileIsNoFormat) {
  load_loopback();
  std::ofstream(dir_ / "spool" / "format", std::ios::binary) << std::string(64, 'x');
  const int fd = open_device(O_RDWR | O_NONBLOCK, kCap);
  ASSERT_GE(fd, 0);
  ::testing::internal::CaptureStderr();
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(ioctl(fd, VIDIOC_G_FMT, &f), -1);
  EXPECT_EQ(errno, EINVAL);
  const std::string said = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("spool/format: expected a spool file (magic \"ARPLOOP1\")"), std::string::npos) << said;
}

}  // namespace
}  // namespace arpipe::standin_test
