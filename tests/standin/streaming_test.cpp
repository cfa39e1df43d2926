// Streaming through the stand-in: the pixels, timestamps and sequence numbers of the recording
// behind it, in every offered format, paced fast or in real time.
#include "standin_fixture.h"

#include <sys/eventfd.h>
#include <turbojpeg.h>

#include <cmath>

#include "core/image/pixel_convert.h"

namespace arpipe::standin_test {
namespace {

using StreamingTest = StandinTest;

void set_format(int fd, uint32_t fourcc) {
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  f.fmt.pix.pixelformat = fourcc;
  ASSERT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), 0);
  ASSERT_EQ(f.fmt.pix.pixelformat, fourcc);
}

TEST_F(StreamingTest, NativePixelsAndStartOfExposureTimestampsAreTheRecordings) {
  load("pacing = \"fast\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  const auto maps = start(fd, 4);
  RecordingReader rec(kDefaultCapture);
  Frame frame;
  for (uint32_t i = 0; i < 6; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b)) << i;
    rec.read(i, frame);
    EXPECT_EQ(b.sequence, i);
    EXPECT_EQ(b.bytesused, frame.data.size());
    EXPECT_EQ(b.field, uint32_t(V4L2_FIELD_NONE));
    EXPECT_EQ(b.flags & (V4L2_BUF_FLAG_TIMESTAMP_MASK | V4L2_BUF_FLAG_TSTAMP_SRC_MASK | V4L2_BUF_FLAG_ERROR),
              uint32_t(V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE));
    // Exact: the recorded exposure start in whole microseconds (timeval).
    EXPECT_EQ(buffer_time_us(b), frame.meta.exposure_start_ns / 1000);
    EXPECT_EQ(std::memcmp(maps[b.index], frame.data.data(), frame.data.size()), 0) << "frame " << i;
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.streamons, 1u);
  EXPECT_EQ(stats.frames_dropped_no_buffer, 0u);  // fast pacing waits for buffers
  EXPECT_GE(stats.frames_delivered, 6u);
}

TEST_F(StreamingTest, EndOfFrameTimestampsAddExposureAndReadout) {
  const auto rec_dir = synthetic_recording(4);
  load("pacing = \"fast\"\ntimestamp_source = \"eof\"\n", rec_dir);
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 2);
  RecordingReader rec(rec_dir);
  for (uint32_t i = 0; i < 4; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    const FrameMetadata& m = rec.metadata(i);
    EXPECT_EQ(b.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK, uint32_t(V4L2_BUF_FLAG_TSTAMP_SRC_EOF));
    EXPECT_EQ(buffer_time_us(b), (m.exposure_start_ns + m.exposure_ns + m.readout_ns) / 1000);
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  // No loop: the recording has ended, poll times out.
  pollfd p{fd, POLLIN, 0};
  EXPECT_EQ(poll(&p, 1, 30), 0);
}

TEST_F(StreamingTest, Rgb24IsTheRecordingConverted) {
  load("pacing = \"fast\"\nformats = [\"native\", \"RGB24\"]\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  set_format(fd, V4L2_PIX_FMT_RGB24);
  const auto maps = start(fd, 2);
  RecordingReader rec(kDefaultCapture);
  Frame frame;
  std::vector<uint8_t> rgb;
  for (uint32_t i = 0; i < 2; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    rec.read(i, frame);
    to_rgb24(frame, rgb);  // arpipe's BT.601 limited-range conversion, as the spec asks
    ASSERT_EQ(b.bytesused, rgb.size());
    EXPECT_EQ(std::memcmp(maps[b.index], rgb.data(), rgb.size()), 0);
  }
}

TEST_F(StreamingTest, MjpegDecodesToTheRecording) {
  load("pacing = \"fast\"\njpeg_quality = 90\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  set_format(fd, V4L2_PIX_FMT_MJPEG);
  const auto maps = start(fd, 2);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));
  RecordingReader rec(kDefaultCapture);
  Frame frame;
  rec.read(0, frame);
  std::vector<uint8_t> expected, decoded(640 * 480 * 3);
  to_rgb24(frame, expected);
  tjhandle dec = tjInitDecompress();
  int w = 0, h = 0, subsampling = -1, colorspace = -1;
  ASSERT_EQ(tjDecompressHeader3(dec, maps[b.index], b.bytesused, &w, &h, &subsampling, &colorspace), 0);
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 480);
  EXPECT_EQ(subsampling, TJSAMP_422);
  ASSERT_EQ(tjDecompress2(dec, maps[b.index], b.bytesused, decoded.data(), 640, 0, 480, TJPF_RGB, 0), 0);
  tjDestroy(dec);
  double sq = 0;
  for (size_t k = 0; k < decoded.size(); ++k) sq += std::pow(double(decoded[k]) - expected[k], 2);
  const double psnr = 10 * std::log10(255.0 * 255.0 / (sq / double(decoded.size())));
  // Quality 90 with 4:2:2 chroma keeps photographic images above ~38 dB; 35 dB leaves room for
  // the simulator's noise and sharp tag edges while catching a wrong layout or colour (< 20 dB).
  EXPECT_GT(psnr, 35.0);
  RecordProperty("mjpeg_psnr_db", std::to_string(psnr));
}

TEST_F(StreamingTest, RealtimePacingFollowsTheRecordedSpacingAndDropsWithoutBuffers) {
  load("pacing = \"realtime\"\ntimestamps = \"live\"\ntimestamp_source = \"eof\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  RecordingReader rec(kDefaultCapture);
  const int64_t interval = rec.metadata(1).exposure_start_ns - rec.metadata(0).exposure_start_ns;
  const int64_t t0 = now_ns();
  start(fd, 4);
  std::vector<int64_t> arrivals, stamps;
  for (int i = 0; i < 4; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    arrivals.push_back(now_ns());
    stamps.push_back(buffer_time_us(b) * 1000);
    EXPECT_EQ(b.sequence, uint32_t(i));
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
  // live + eof: the first frame's end of exposure is the STREAMON time, the rest keep the recorded spacing.
  EXPECT_NEAR(double(stamps[0] - t0), 0.0, 20e6);
  for (int i = 1; i < 4; ++i) EXPECT_NEAR(double(stamps[i] - stamps[i - 1]), double(interval), 1e3);  // µs rounding
  // Arrivals: on schedule within a loose 15 ms (a busy CI machine); three intervals in all.
  EXPECT_NEAR(double(arrivals[3] - arrivals[0]), 3.0 * double(interval), 15e6);

  // Hold every buffer for about three intervals: the frames due meanwhile are dropped and counted.
  std::vector<uint32_t> held;
  for (int i = 0; i < 4; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    held.push_back(b.index);
  }
  usleep(useconds_t(3.5 * double(interval) / 1000));
  for (uint32_t index : held) ASSERT_EQ(qbuf(fd, index), 0);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));
  EXPECT_GE(b.sequence, 11u);  // 8 delivered (0..7), at least 3 dropped
  struct arpipe_v4l2_standin_stats stats{};
  ASSERT_EQ(arpipe_v4l2_standin_stats(kDevice, &stats), 0);
  EXPECT_EQ(stats.frames_dropped_no_buffer, b.sequence - 8);
}

TEST_F(StreamingTest, LoopContinuesTimestampsLikeAReplay) {
  const auto rec_dir = synthetic_recording(3);
  load("pacing = \"fast\"\nloop = true\n", rec_dir);
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  start(fd, 2);
  RecordingReader rec(rec_dir);
  // period = (end of the last exposure - end of the first) + one interval
  const int64_t end0 = rec.metadata(0).exposure_start_ns + rec.metadata(0).exposure_ns + rec.metadata(0).readout_ns;
  const int64_t end2 = rec.metadata(2).exposure_start_ns + rec.metadata(2).exposure_ns + rec.metadata(2).readout_ns;
  const int64_t period = end2 - end0 + rec.metadata(0).frame_duration_ns;
  for (uint32_t i = 0; i < 7; ++i) {
    v4l2_buffer b{};
    ASSERT_TRUE(next_buffer(fd, b));
    EXPECT_EQ(b.sequence, i);
    EXPECT_EQ(buffer_time_us(b), (rec.metadata(i % 3).exposure_start_ns + int64_t(i / 3) * period) / 1000);
    ASSERT_EQ(qbuf(fd, b.index), 0);
  }
}

TEST_F(StreamingTest, PollMixesServedAndRealDescriptors) {
  load("pacing = \"realtime\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  const int efd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  ASSERT_GE(efd, 0);
  // Not streaming, and the real eventfd signalled: both report at once.
  ASSERT_EQ(eventfd_write(efd, 1), 0);
  pollfd p[2] = {{efd, POLLIN, 0}, {fd, POLLIN, 0}};
  EXPECT_EQ(poll(p, 2, 100), 2);
  EXPECT_EQ(p[0].revents, POLLIN);
  EXPECT_EQ(p[1].revents, POLLERR);
  eventfd_t v;
  eventfd_read(efd, &v);
  start(fd, 2);
  v4l2_buffer b{};
  ASSERT_TRUE(next_buffer(fd, b));  // frame 0 falls due at STREAMON
  ASSERT_EQ(dqbuf(fd, b), -1);
  // The next frame is due one interval later: a poll on both wakes for it, not for the quiet eventfd.
  p[1].revents = p[0].revents = 0;
  const int64_t t = now_ns();
  EXPECT_EQ(poll(p, 2, 1000), 1);
  EXPECT_EQ(p[1].revents, POLLIN);  // what was asked for (POLLRDNORM was not)
  EXPECT_EQ(p[0].revents, 0);
  EXPECT_LT(now_ns() - t, 100000000);
  ::close(efd);
}

}  // namespace
}  // namespace arpipe::standin_test
