// Format negotiation and the buffer-queue rules of the stand-in against the V4L2 specification
// (and uvcvideo/videobuf2 where the specification lets drivers choose).
#include "standin_fixture.h"

#include <turbojpeg.h>

namespace arpipe::standin_test {
namespace {

using NegotiationTest = StandinTest;

TEST_F(NegotiationTest, CapabilitiesFormatsSizesIntervals) {
  load("pacing = \"fast\"\ncard = \"Test Cam\"\nformats = [\"native\", \"MJPG\", \"RGB24\"]\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  v4l2_capability cap{};
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERYCAP, &cap), 0);
  EXPECT_STREQ(reinterpret_cast<const char*>(cap.card), "Test Cam");
  EXPECT_STREQ(reinterpret_cast<const char*>(cap.bus_info), "platform:arpipe-standin-0");
  EXPECT_EQ(cap.device_caps, uint32_t(V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT));
  EXPECT_EQ(cap.capabilities, cap.device_caps | V4L2_CAP_DEVICE_CAPS);

  const uint32_t expected[] = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_RGB24};
  for (uint32_t i = 0; i < 4; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (i == 3) {
      EXPECT_EQ(ioctl(fd, VIDIOC_ENUM_FMT, &d), -1);
      EXPECT_EQ(errno, EINVAL);
      break;
    }
    ASSERT_EQ(ioctl(fd, VIDIOC_ENUM_FMT, &d), 0);
    EXPECT_EQ(d.pixelformat, expected[i]);
    EXPECT_EQ(d.flags, expected[i] == V4L2_PIX_FMT_MJPEG ? uint32_t(V4L2_FMT_FLAG_COMPRESSED) : 0u);
  }
  v4l2_frmsizeenum s{};
  s.pixel_format = V4L2_PIX_FMT_MJPEG;
  ASSERT_EQ(ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s), 0);
  EXPECT_EQ(s.type, uint32_t(V4L2_FRMSIZE_TYPE_DISCRETE));
  EXPECT_EQ(s.discrete.width, 640u);
  EXPECT_EQ(s.discrete.height, 480u);
  s.index = 1;
  EXPECT_EQ(ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s), -1);
  s = {};
  s.pixel_format = V4L2_PIX_FMT_NV12;  // not offered
  EXPECT_EQ(ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s), -1);

  // The recording's frame_duration_ns (33333333) as a reduced fraction of a second.
  RecordingReader rec(kDefaultCapture);
  v4l2_frmivalenum iv{};
  iv.pixel_format = V4L2_PIX_FMT_YUYV;
  iv.width = 640;
  iv.height = 480;
  ASSERT_EQ(ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv), 0);
  EXPECT_EQ(iv.type, uint32_t(V4L2_FRMIVAL_TYPE_DISCRETE));
  EXPECT_EQ(int64_t(iv.discrete.numerator) * 1000000000, rec.metadata(0).frame_duration_ns * int64_t(iv.discrete.denominator));
  iv.width = 320;
  EXPECT_EQ(ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv), -1);

  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  parm.parm.capture.timeperframe = {1, 5};
  ASSERT_EQ(ioctl(fd, VIDIOC_S_PARM, &parm), 0);  // any request gets the one interval
  EXPECT_EQ(parm.parm.capture.capability, uint32_t(V4L2_CAP_TIMEPERFRAME));
  EXPECT_EQ(parm.parm.capture.timeperframe.numerator, iv.discrete.numerator);
  EXPECT_EQ(parm.parm.capture.timeperframe.denominator, iv.discrete.denominator);

  v4l2_input in{};
  ASSERT_EQ(ioctl(fd, VIDIOC_ENUMINPUT, &in), 0);
  EXPECT_EQ(in.type, uint32_t(V4L2_INPUT_TYPE_CAMERA));
  in.index = 1;
  EXPECT_EQ(ioctl(fd, VIDIOC_ENUMINPUT, &in), -1);
  int input = 5;
  ASSERT_EQ(ioctl(fd, VIDIOC_G_INPUT, &input), 0);
  EXPECT_EQ(input, 0);
}

TEST_F(NegotiationTest, SetFormatAdjustsToWhatIsOffered) {
  load("pacing = \"fast\"\nformats = [\"MJPG\", \"native\", \"NV12\"]\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(ioctl(fd, VIDIOC_G_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_MJPEG));  // the first offered
  EXPECT_EQ(f.fmt.pix.sizeimage, uint32_t(tjBufSize(640, 480, TJSAMP_422)));

  f = {};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  f.fmt.pix = {1920, 1080, V4L2_PIX_FMT_NV12, V4L2_FIELD_INTERLACED, 0, 0, 0, 0, 0, 0, 0, 0};
  ASSERT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.width, 640u);  // the only size
  EXPECT_EQ(f.fmt.pix.height, 480u);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_NV12));
  EXPECT_EQ(f.fmt.pix.field, uint32_t(V4L2_FIELD_NONE));
  EXPECT_EQ(f.fmt.pix.bytesperline, 640u);
  EXPECT_EQ(f.fmt.pix.sizeimage, 640u * 480 * 3 / 2);
  EXPECT_EQ(f.fmt.pix.quantization, uint32_t(V4L2_QUANTIZATION_LIM_RANGE));

  f.fmt.pix.pixelformat = v4l2_fourcc('H', '2', '6', '4');  // unknown: the first offered
  ASSERT_EQ(ioctl(fd, VIDIOC_TRY_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_MJPEG));
  EXPECT_EQ(f.fmt.pix.bytesperline, 0u);
  f = {};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(ioctl(fd, VIDIOC_G_FMT, &f), 0);
  EXPECT_EQ(f.fmt.pix.pixelformat, uint32_t(V4L2_PIX_FMT_NV12));  // TRY_FMT changed nothing

  f.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  setup_buffers(fd, 2);
  EXPECT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), -1);  // buffers allocated
  EXPECT_EQ(errno, EBUSY);
  f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  EXPECT_EQ(ioctl(fd, VIDIOC_G_FMT, &f), -1);
  EXPECT_EQ(errno, EINVAL);
}

TEST_F(NegotiationTest, BufferQueueErrorCodes) {
  load("pacing = \"fast\"\n");
  const int fd = open_device();
  ASSERT_GE(fd, 0);
  v4l2_requestbuffers r{};
  r.count = 4;
  r.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  r.memory = V4L2_MEMORY_USERPTR;
  EXPECT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), -1);
  EXPECT_EQ(errno, EINVAL);
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(ioctl(fd, VIDIOC_STREAMON, &type), -1);  // no buffers
  EXPECT_EQ(errno, EINVAL);
  r.memory = V4L2_MEMORY_MMAP;
  r.count = 100;
  ASSERT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0);
  EXPECT_EQ(r.count, 32u);
  EXPECT_TRUE(r.capabilities & V4L2_BUF_CAP_SUPPORTS_MMAP);
  r.count = 3;
  ASSERT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0);
  EXPECT_EQ(r.count, 3u);

  // Another file handle may look but not touch the queue.
  const int other = open_device();
  ASSERT_GE(other, 0);
  EXPECT_EQ(ioctl(other, VIDIOC_REQBUFS, &r), -1);
  EXPECT_EQ(errno, EBUSY);
  EXPECT_EQ(qbuf(other, 0), -1);
  EXPECT_EQ(errno, EBUSY);

  v4l2_buffer b{};
  EXPECT_EQ(dqbuf(fd, b), -1);  // not streaming
  EXPECT_EQ(errno, EINVAL);
  EXPECT_EQ(qbuf(fd, 3), -1);
  EXPECT_EQ(errno, EINVAL);
  ASSERT_EQ(qbuf(fd, 0), 0);
  EXPECT_EQ(qbuf(fd, 0), -1);  // already queued
  EXPECT_EQ(errno, EINVAL);
  b = {};
  b.index = 1;
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_USERPTR;
  EXPECT_EQ(ioctl(fd, VIDIOC_QBUF, &b), -1);
  EXPECT_EQ(errno, EINVAL);

  // Two mappings of one buffer see the same bytes; a mapping at no buffer's offset is refused.
  b = {};
  b.index = 0;
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  ASSERT_EQ(ioctl(fd, VIDIOC_QUERYBUF, &b), 0);
  EXPECT_EQ(b.length, 640u * 480 * 2);
  EXPECT_EQ(b.flags & (V4L2_BUF_FLAG_QUEUED | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE),
            uint32_t(V4L2_BUF_FLAG_QUEUED | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE));
  auto* m1 = static_cast<uint8_t*>(mmap(nullptr, b.length, PROT_READ, MAP_SHARED, fd, b.m.offset));
  auto* m2 = static_cast<uint8_t*>(mmap(nullptr, b.length, PROT_READ, MAP_SHARED, fd, b.m.offset));
  ASSERT_NE(m1, MAP_FAILED);
  ASSERT_NE(m2, MAP_FAILED);
  maps_.push_back({m1, b.length});
  maps_.push_back({m2, b.length});
  EXPECT_EQ(mmap(nullptr, b.length, PROT_READ, MAP_PRIVATE, fd, b.m.offset), MAP_FAILED);
  EXPECT_EQ(mmap(nullptr, b.length, PROT_READ, MAP_SHARED, fd, b.m.offset + 4096), MAP_FAILED);
  EXPECT_EQ(errno, EINVAL);

  ASSERT_EQ(ioctl(fd, VIDIOC_STREAMON, &type), 0);
  EXPECT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), -1);  // streaming
  EXPECT_EQ(errno, EBUSY);
  ASSERT_EQ(dqbuf(fd, b), 0);  // fast pacing: the queued buffer is done at once
  EXPECT_EQ(b.index, 0u);
  EXPECT_EQ(b.sequence, 0u);
  EXPECT_EQ(std::memcmp(m1, m2, b.bytesused), 0);
  EXPECT_EQ(dqbuf(fd, b), -1);  // O_NONBLOCK, nothing done
  EXPECT_EQ(errno, EAGAIN);

  // STREAMOFF hands every buffer back, done ones cleared.
  ASSERT_EQ(qbuf(fd, 0), 0);
  ASSERT_EQ(qbuf(fd, 1), 0);
  ASSERT_EQ(ioctl(fd, VIDIOC_STREAMOFF, &type), 0);
  for (uint32_t i = 0; i < 3; ++i) {
    b = {};
    b.index = i;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    ASSERT_EQ(ioctl(fd, VIDIOC_QUERYBUF, &b), 0);
    EXPECT_EQ(b.flags & (V4L2_BUF_FLAG_QUEUED | V4L2_BUF_FLAG_DONE), 0u);
  }
  pollfd p{fd, POLLIN, 0};
  ASSERT_EQ(poll(&p, 1, 0), 1);
  EXPECT_EQ(p.revents, POLLERR);  // not streaming (videobuf2)

  EXPECT_EQ(ioctl(fd, VIDIOC_G_STD, &type), -1);
  EXPECT_EQ(errno, ENOTTY);
  char byte;
  EXPECT_EQ(read(fd, &byte, 1), -1);
  EXPECT_EQ(errno, EINVAL);
  r.count = 0;
  ASSERT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0);  // frees; the mappings stay readable (orphaned)
  EXPECT_EQ(m1[0], m2[0]);
  EXPECT_EQ(ioctl(other, VIDIOC_REQBUFS, &r), 0);  // the queue has no owner now
}

}  // namespace
}  // namespace arpipe::standin_test
