// Each fault kind of the stand-in: unplug and replug, stall, drop, error buffer, EAGAIN storm, EIO.
#include "standin_fixture.h"

namespace arpipe::standin_test {
namespace {

using FaultsTest = StandinTest;

std::string fault(int frame, const std::string& kind, const std::string& extra = "") {
  return "[[device.fault]]\nframe = " + std::to_string(frame) + "\nkind = \"" + kind + "\"\n" + extra;
}

TEST_F(FaultsTest, UnplugMidStreamAndReplug) {
  load("pacing = \"fast\"\n" + fault(3, "unplug", "replug_after_ms = 150\n"));
  RecordingReader rec(kDefaultCapture);
  int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 1);
  for (uint32_t i = 0; i < 3; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    EXPECT_EQ(buffer_time_us(b), rec.metadata(i).exposure_start_ns / 1000);
    ASSERT_EQ(qbuf(fd, b.index), 0);  // the third lets frame 3 fall due: the camera goes away
  }
  v4l2_capability cap{};
  EXPECT_EQ(ioctl(fd, VIDIOC_QUERYCAP, &cap), -1);
  EXPECT_EQ(errno, ENODEV);
  pollfd p{fd, POLLIN | POLLPRI, 0};
  ASSERT_EQ(poll(&p, 1, 0), 1);
  EXPECT_EQ(p.revents, POLLERR | POLLHUP);
  v4l2_buffer b{};
  EXPECT_EQ(dqbuf(fd, b), -1);
  EXPECT_EQ(errno, ENODEV);
  EXPECT_EQ(mmap(nullptr, 4096, PROT_READ, MAP_SHARED, fd, 0), MAP_FAILED);
  EXPECT_EQ(errno, ENODEV);
  EXPECT_EQ(open_device(), -1);
  EXPECT_EQ(errno, ENOENT);
  close_device(fd);

  // Back after 150 ms: a new open streams on; fast pacing continues after the lost frame 3.
  fd = -1;
  for (int tries = 0; tries < 100 && fd < 0; ++tries) {
    usleep(10000);
    fd = open_device();
  }
  ASSERT_GE(fd, 0);
  start(fd, 2);
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_EQ(b.sequence, 0u);  // a new stream counts from 0
  EXPECT_EQ(buffer_time_us(b), rec.metadata(4).exposure_start_ns / 1000);
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.unplugs, 1u);
  EXPECT_EQ(stats.opens, 2u);
  EXPECT_EQ(stats.streamons, 2u);
}

TEST_F(FaultsTest, StallHoldsFramesBack) {
  load("pacing = \"fast\"\n" + fault(2, "stall", "duration_ms = 200\n"));
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 2);
  v4l2_buffer b{};
  for (uint32_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(next_buffer(fd, b));
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  const int64_t t = now_ns();
  pollfd p{fd, POLLIN, 0};
  EXPECT_EQ(poll(&p, 1, 50), 0);  // a timeout for the host
  ASSERT_TRUE(next_buffer(fd, b, 1000));
  EXPECT_EQ(b.sequence, 2u);
  EXPECT_NEAR(double(now_ns() - t), 200e6, 60e6);
}

TEST_F(FaultsTest, DropMakesTheSequenceJump) {
  load("pacing = \"fast\"\n" + fault(2, "drop", "count = 3\n"));
  RecordingReader rec(kDefaultCapture);
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 2);
  const uint32_t expected[] = {0, 1, 5, 6};
  for (uint32_t s : expected) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    EXPECT_EQ(b.sequence, s);
    EXPECT_EQ(buffer_time_us(b), rec.metadata(s).exposure_start_ns / 1000);
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.frames_skipped_by_fault, 3u);
}

TEST_F(FaultsTest, ErrorBufferEagainAndEio) {
  load("pacing = \"fast\"\n" + fault(1, "error_buffer") + fault(2, "eagain", "count = 2\n") + fault(3, "eio"));
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 1);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_EQ(b.flags & V4L2_BUF_FLAG_ERROR, 0u);
  ASSERT_EQ(qbuf(fd, b.index), 0);
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_EQ(b.sequence, 1u);
  EXPECT_EQ(b.flags & V4L2_BUF_FLAG_ERROR, uint32_t(V4L2_BUF_FLAG_ERROR));
  ASSERT_EQ(qbuf(fd, b.index), 0);
  // Frame 2: two wake-ups where poll says POLLIN and DQBUF says EAGAIN, then the buffer.
  for (int k = 0; k < 2; ++k) {
    pollfd p{fd, POLLIN, 0};
    ASSERT_EQ(poll(&p, 1, 100), 1);
    EXPECT_EQ(dqbuf(fd, b), -1);
    EXPECT_EQ(errno, EAGAIN);
  }
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_EQ(b.sequence, 2u);
  EXPECT_EQ(b.flags & V4L2_BUF_FLAG_ERROR, 0u);
  ASSERT_EQ(qbuf(fd, b.index), 0);
  // Frame 3: the next DQBUF fails with EIO once.
  EXPECT_EQ(dqbuf(fd, b), -1);
  EXPECT_EQ(errno, EIO);
  ASSERT_EQ(dqbuf(fd, b), 0);
  EXPECT_EQ(b.sequence, 3u);
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.error_buffers, 1u);
}

TEST_F(FaultsTest, RealtimeUnplugLosesTheFramesDueWhileAway) {
  load("pacing = \"realtime\"\n" + fault(1, "unplug", "replug_after_ms = 100\n"));
  RecordingReader rec(kDefaultCapture);
  int fd = open_device();
  ASSERT_GE(fd, 0);
  const int64_t t0 = now_ns();
  start(fd, 2);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));
  pollfd p{fd, POLLIN, 0};
  ASSERT_EQ(poll(&p, 1, 1000), 1);
  EXPECT_EQ(p.revents, POLLERR | POLLHUP);
  close_device(fd);
  fd = -1;
  while (fd < 0 && now_ns() - t0 < 2000000000) {
    usleep(5000);
    fd = open_device();
  }
  ASSERT_GE(fd, 0);
  start(fd, 2);
  ASSERT_TRUE(next_buffer(fd, b));
  // Unplugged at frame 1's due time (~33 ms), back ~100 ms later: frames 1..4 fell due while away.
  const int64_t interval = rec.metadata(1).exposure_start_ns - rec.metadata(0).exposure_start_ns;
  const int64_t first = (int64_t(buffer_time_us(b)) * 1000 - rec.metadata(0).exposure_start_ns + interval / 2) / interval;
  EXPECT_GE(first, 4);
  EXPECT_LE(first, 8);  // a loose bound for a slow machine
  EXPECT_EQ(b.sequence, 0u);
}

}  // namespace
}  // namespace arpipe::standin_test
