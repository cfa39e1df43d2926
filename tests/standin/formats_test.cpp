// The formats made by reordering YUYV/NV12 (UYVY, YVYU, NV21, YU12, NV16) and the multi-planar
// path (VIDEO_CAPTURE_MPLANE, split planes): bytes equal to an independent reordering of the
// recording's frame, sequence numbers and timestamps exact.
#include "standin_fixture.h"

#include "core/image/pixel_convert.h"

namespace arpipe::standin_test {
namespace {

constexpr int kW = 640, kH = 480;

// The recording's frame i as packed YUYV (it is recorded in YUYV) and as arpipe's NV12 of it.
struct Basis {
  std::vector<uint8_t> yuyv, nv12;
};
Basis basis(RecordingReader& rec, size_t i) {
  Frame frame;
  rec.read(i, frame);
  EXPECT_EQ(frame.format, PixelFormat::YUYV);
  Basis b;
  for (int r = 0; r < kH; ++r)
    b.yuyv.insert(b.yuyv.end(), frame.data.begin() + ptrdiff_t(size_t(r) * frame.bytes_per_line),
                  frame.data.begin() + ptrdiff_t(size_t(r) * frame.bytes_per_line + kW * 2));
  std::vector<uint8_t> rgb;
  to_rgb24(frame, rgb);
  b.nv12 = from_rgb24(rgb.data(), kW, kH, PixelFormat::NV12).data;
  return b;
}

// Each layout written out the slow, obvious way (pixel by pixel from its definition).
std::vector<uint8_t> expected(uint32_t fourcc, const Basis& b) {
  std::vector<uint8_t> out;
  const size_t n = size_t(kW) * kH;
  switch (fourcc) {
    case V4L2_PIX_FMT_UYVY:
    case V4L2_PIX_FMT_YVYU:
      for (size_t k = 0; k < b.yuyv.size(); k += 4) {
        const uint8_t y0 = b.yuyv[k], u = b.yuyv[k + 1], y1 = b.yuyv[k + 2], v = b.yuyv[k + 3];
        if (fourcc == V4L2_PIX_FMT_UYVY) out.insert(out.end(), {u, y0, v, y1});
        else out.insert(out.end(), {y0, v, y1, u});
      }
      break;
    case V4L2_PIX_FMT_NV16:
    case V4L2_PIX_FMT_NV16M:
      out.resize(2 * n);
      for (size_t p = 0; p < n; ++p) {
        out[p] = b.yuyv[2 * p];                                     // Y of pixel p
        out[n + p] = b.yuyv[4 * (p / 2) + ((p % 2) == 0 ? 1 : 3)];  // U for even, V for odd columns
      }
      break;
    case V4L2_PIX_FMT_NV12M: out = b.nv12; break;
    case V4L2_PIX_FMT_NV21:
    case V4L2_PIX_FMT_NV21M:
      out = b.nv12;
      for (size_t k = n; k < out.size(); k += 2) std::swap(out[k], out[k + 1]);
      break;
    case V4L2_PIX_FMT_YUV420:
    case V4L2_PIX_FMT_YUV420M:
      out.assign(b.nv12.begin(), b.nv12.begin() + ptrdiff_t(n));
      for (int plane = 0; plane < 2; ++plane)
        for (size_t k = n + size_t(plane); k < b.nv12.size(); k += 2) out.push_back(b.nv12[k]);
      break;
  }
  return out;
}

using FormatsTest = StandinTest;

TEST_F(FormatsTest, ReorderedFormatsStreamTheRecordingExactly) {
  load("pacing = \"fast\"\nformats = [\"native\", \"UYVY\", \"YVYU\", \"NV21\", \"YU12\", \"NV16\"]\n");
  RecordingReader rec(kDefaultCapture);
  for (const uint32_t fourcc : {V4L2_PIX_FMT_UYVY, V4L2_PIX_FMT_YVYU, V4L2_PIX_FMT_NV21, V4L2_PIX_FMT_YUV420, V4L2_PIX_FMT_NV16}) {
    const int fd = open_device();
    ASSERT_GE(fd, 0);
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.pixelformat = fourcc;
    ASSERT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), 0);
    ASSERT_EQ(f.fmt.pix.pixelformat, fourcc);
    const bool packed = fourcc == V4L2_PIX_FMT_UYVY || fourcc == V4L2_PIX_FMT_YVYU;
    EXPECT_EQ(f.fmt.pix.bytesperline, packed ? 2u * kW : uint32_t(kW));
    EXPECT_EQ(f.fmt.pix.sizeimage, fourcc == V4L2_PIX_FMT_NV21 || fourcc == V4L2_PIX_FMT_YUV420 ? kW * kH * 3u / 2 : kW * kH * 2u);
    EXPECT_EQ(f.fmt.pix.quantization, uint32_t(V4L2_QUANTIZATION_LIM_RANGE));
    const auto maps = start(fd, 2);
    for (uint32_t i = 0; i < 3; ++i) {
      v4l2_buffer b{};
      ASSERT_TRUE(next_buffer(fd, b)) << fourcc << " frame " << i;
      const std::vector<uint8_t> want = expected(fourcc, basis(rec, i));
      EXPECT_EQ(b.sequence, i);
      EXPECT_EQ(buffer_time_us(b), rec.metadata(i).exposure_start_ns / 1000);
      ASSERT_EQ(b.bytesused, want.size());
      EXPECT_EQ(std::memcmp(maps[b.index], want.data(), want.size()), 0) << fourcc << " frame " << i;
      ASSERT_EQ(qbuf(fd, b.index), 0);
    }
    close_device(fd);
  }
}

TEST_F(FormatsTest, MultiPlanarServesEachPlaneByItsOffset) {
  load("pacing = \"fast\"\nbuffer_type = \"mplane\"\nformats = [\"native\", \"NV12M\", \"YUV420M\", \"NV21M\", \"NV16M\", \"UYVY\"]\n");
  const int fd0 = open_device();
  ASSERT_GE(fd0, 0);
  v4l2_capability cap{};
  ASSERT_EQ(ioctl(fd0, VIDIOC_QUERYCAP, &cap), 0);
  EXPECT_EQ(cap.device_caps, uint32_t(V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT));
  v4l2_fmtdesc desc{};
  desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  EXPECT_EQ(ioctl(fd0, VIDIOC_ENUM_FMT, &desc), -1);  // the single-planar type is not this device's
  desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
  desc.index = 2;
  ASSERT_EQ(ioctl(fd0, VIDIOC_ENUM_FMT, &desc), 0);
  EXPECT_EQ(desc.pixelformat, uint32_t(V4L2_PIX_FMT_YUV420M));
  close_device(fd0);

  RecordingReader rec(kDefaultCapture);
  const size_t n = size_t(kW) * kH;
  struct Case {
    uint32_t fourcc;
    std::vector<uint32_t> bytesperline, sizes;
  };
  const Case cases[] = {{V4L2_PIX_FMT_YUYV, {2 * kW}, {uint32_t(2 * n)}},
                        {V4L2_PIX_FMT_NV12M, {kW, kW}, {uint32_t(n), uint32_t(n / 2)}},
                        {V4L2_PIX_FMT_YUV420M, {kW, kW / 2, kW / 2}, {uint32_t(n), uint32_t(n / 4), uint32_t(n / 4)}},
                        {V4L2_PIX_FMT_NV21M, {kW, kW}, {uint32_t(n), uint32_t(n / 2)}},
                        {V4L2_PIX_FMT_NV16M, {kW, kW}, {uint32_t(n), uint32_t(n)}},
                        {V4L2_PIX_FMT_UYVY, {2 * kW}, {uint32_t(2 * n)}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.fourcc);
    const int fd = open_device();
    ASSERT_GE(fd, 0);
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
    f.fmt.pix_mp.pixelformat = c.fourcc;
    ASSERT_EQ(ioctl(fd, VIDIOC_S_FMT, &f), 0);
    ASSERT_EQ(f.fmt.pix_mp.pixelformat, c.fourcc);
    ASSERT_EQ(f.fmt.pix_mp.num_planes, c.sizes.size());
    for (size_t p = 0; p < c.sizes.size(); ++p) {
      EXPECT_EQ(f.fmt.pix_mp.plane_fmt[p].bytesperline, c.bytesperline[p]);
      EXPECT_EQ(f.fmt.pix_mp.plane_fmt[p].sizeimage, c.sizes[p]);
    }
    v4l2_requestbuffers r{};
    r.count = 2;
    r.type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
    r.memory = V4L2_MEMORY_MMAP;
    ASSERT_EQ(ioctl(fd, VIDIOC_REQBUFS, &r), 0);
    std::vector<std::vector<uint8_t*>> maps(r.count);
    for (uint32_t i = 0; i < r.count; ++i) {
      v4l2_plane planes[VIDEO_MAX_PLANES]{};
      v4l2_buffer b{};
      b.index = i;
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
      b.memory = V4L2_MEMORY_MMAP;
      b.m.planes = planes;
      b.length = VIDEO_MAX_PLANES;
      ASSERT_EQ(ioctl(fd, VIDIOC_QUERYBUF, &b), 0);
      ASSERT_EQ(b.length, c.sizes.size());
      for (uint32_t p = 0; p < b.length; ++p) {
        EXPECT_EQ(planes[p].length, c.sizes[p]);
        void* m = mmap(nullptr, planes[p].length, PROT_READ, MAP_SHARED, fd, planes[p].m.mem_offset);
        ASSERT_NE(m, MAP_FAILED) << strerror(errno);
        maps_.push_back({m, planes[p].length});
        maps[i].push_back(static_cast<uint8_t*>(m));
      }
      ASSERT_EQ(ioctl(fd, VIDIOC_QBUF, &b), 0);
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
    ASSERT_EQ(ioctl(fd, VIDIOC_STREAMON, &type), 0);
    for (uint32_t i = 0; i < 3; ++i) {
      pollfd pfd{fd, POLLIN, 0};
      ASSERT_EQ(poll(&pfd, 1, 1000), 1);
      v4l2_plane planes[VIDEO_MAX_PLANES]{};
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
      b.memory = V4L2_MEMORY_MMAP;
      b.m.planes = planes;
      b.length = VIDEO_MAX_PLANES;
      ASSERT_EQ(ioctl(fd, VIDIOC_DQBUF, &b), 0);
      EXPECT_EQ(b.sequence, i);
      EXPECT_EQ(buffer_time_us(b), rec.metadata(i).exposure_start_ns / 1000);
      const Basis basis_i = basis(rec, i);
      const std::vector<uint8_t> want = c.fourcc == V4L2_PIX_FMT_YUYV ? basis_i.yuyv : expected(c.fourcc, basis_i);
      size_t at = 0;
      for (uint32_t p = 0; p < c.sizes.size(); ++p) {
        EXPECT_EQ(planes[p].bytesused, c.sizes[p]);
        EXPECT_EQ(planes[p].data_offset, 0u);
        EXPECT_EQ(std::memcmp(maps[b.index][p], want.data() + at, c.sizes[p]), 0) << "plane " << p << " frame " << i;
        at += c.sizes[p];
      }
      EXPECT_EQ(at, want.size());
      ASSERT_EQ(ioctl(fd, VIDIOC_QBUF, &b), 0);
    }
    ASSERT_EQ(ioctl(fd, VIDIOC_STREAMOFF, &type), 0);
    close_device(fd);
  }
}

TEST_F(FormatsTest, SplitFormatsNeedMultiPlanarBuffersAndTheirPlaceIsNamed) {
  const std::string head = "[[device]]\npath = \"/dev/video42\"\nrecording = \"" + kDefaultCapture.string() + "\"\n";
  char error[512] = "";
  EXPECT_EQ(arpipe_v4l2_standin_load(write_config(head + "formats = [\"native\", \"NV12M\"]\n").c_str(), error, sizeof error), -1);
  EXPECT_NE(std::string(error).find("standin.toml:4:11: device[0].formats: format \"NV12M\" has split planes: it needs buffer_type = \"mplane\""),
            std::string::npos) << error;
  EXPECT_EQ(arpipe_v4l2_standin_load(write_config(head + "buffer_type = \"multi\"\n").c_str(), error, sizeof error), -1);
  EXPECT_NE(std::string(error).find("standin.toml:4:15: device[0].buffer_type: expected one of \"single\", \"mplane\""),
            std::string::npos) << error;
  EXPECT_EQ(arpipe_v4l2_standin_load(write_config(head + "formats = [\"NV12\", \"YU12\", \"I420\"]\n").c_str(), error, sizeof error), -1);
  EXPECT_NE(std::string(error).find("standin.toml:4:11: device[0].formats: expected an array of formats"), std::string::npos) << error;
}

}  // namespace
}  // namespace arpipe::standin_test
