// The V4L2 formats the source reorders while copying (capture/v4l2/v4l2_frame_layout.h): each one,
// built here byte by byte from random Y, U and V samples with padded strides as a driver may give,
// must become exactly the YUYV or NV12 frame of the same samples.
#include "capture/v4l2/v4l2_frame_layout.h"

#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include <random>
#include <vector>

namespace arpipe {
namespace {

constexpr int kW = 38, kH = 22;  // even, and not a multiple of any alignment

struct Samples {
  std::vector<uint8_t> y, u, v;  // y: w x h; u, v: (w/2) x (h / vertical)
  int vertical = 1;              // chroma rows per luma row: 1 (4:2:2) or 2 (4:2:0)
  uint8_t Y(int x, int r) const { return y[size_t(r * kW + x)]; }
  uint8_t U(int i, int r) const { return u[size_t(r / vertical * kW / 2 + i)]; }
  uint8_t V(int i, int r) const { return v[size_t(r / vertical * kW / 2 + i)]; }
};

Samples random_samples(int vertical, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  Samples s;
  s.vertical = vertical;
  s.y.resize(size_t(kW * kH));
  s.u.resize(size_t(kW / 2 * kH / vertical));
  s.v.resize(s.u.size());
  for (auto* plane : {&s.y, &s.u, &s.v})
    for (auto& b : *plane) b = uint8_t(byte(rng));
  return s;
}

// The frames the pipeline must get: YUYV (Y0 U Y1 V) and NV12 (Y, then U V pairs), minimum stride.
std::vector<uint8_t> yuyv_of(const Samples& s) {
  std::vector<uint8_t> out;
  for (int r = 0; r < kH; ++r)
    for (int i = 0; i < kW / 2; ++i) out.insert(out.end(), {s.Y(2 * i, r), s.U(i, r), s.Y(2 * i + 1, r), s.V(i, r)});
  return out;
}
std::vector<uint8_t> nv12_of(const Samples& s) {
  std::vector<uint8_t> out(s.y);
  for (int r = 0; r < kH; r += 2)
    for (int i = 0; i < kW / 2; ++i) out.insert(out.end(), {s.U(i, r), s.V(i, r)});
  return out;
}

// A plane of `rows` rows of `row` bytes each, padded to `stride` with 0xEE (never a sample to copy).
struct PlaneBytes {
  std::vector<uint8_t> bytes;
  size_t stride = 0;
  void add_row(const std::vector<uint8_t>& row) {
    std::vector<uint8_t> padded(row);
    padded.resize(stride, 0xEE);
    bytes.insert(bytes.end(), padded.begin(), padded.end());
  }
};

V4L2FrameLayout layout(uint32_t fourcc) {
  const auto l = v4l2_frame_layout(fourcc);
  EXPECT_TRUE(l.has_value());
  return *l;
}

Frame fill(uint32_t fourcc, const std::vector<PlaneBytes>& planes) {
  std::vector<V4L2Plane> in;
  for (const auto& p : planes) in.push_back({p.bytes.data(), p.bytes.size(), p.stride});
  Frame frame;
  bool allocated = false;
  std::string why;
  EXPECT_TRUE(fill_frame_from_v4l2(layout(fourcc), in, kW, kH, frame, allocated, why)) << why;
  EXPECT_TRUE(allocated);  // a new Frame holds nothing
  return frame;
}

TEST(V4L2FrameLayout, PackedOrdersBecomeYuyv) {
  const Samples s = random_samples(1, 1);
  // Byte order per pixel pair, as the V4L2 specification lists them.
  const std::pair<uint32_t, std::array<char, 4>> orders[] = {{V4L2_PIX_FMT_UYVY, {'U', 'Y', 'V', 'y'}},
                                                             {V4L2_PIX_FMT_YVYU, {'Y', 'V', 'y', 'U'}}};
  for (const auto& [fourcc, order] : orders) {
    PlaneBytes plane{{}, 2 * kW + 6};
    for (int r = 0; r < kH; ++r) {
      std::vector<uint8_t> row;
      for (int i = 0; i < kW / 2; ++i)
        for (const char c : order)
          row.push_back(c == 'Y' ? s.Y(2 * i, r) : c == 'y' ? s.Y(2 * i + 1, r) : c == 'U' ? s.U(i, r) : s.V(i, r));
      plane.add_row(row);
    }
    const Frame frame = fill(fourcc, {plane});
    EXPECT_EQ(frame.format, PixelFormat::YUYV);
    EXPECT_EQ(frame.bytes_per_line, size_t(2 * kW));
    EXPECT_EQ(frame.data, yuyv_of(s)) << fourcc;
  }
}

// The chroma of a semi-planar format: U V (or V U) pairs, one row per `vertical` luma rows.
std::vector<PlaneBytes> semi_planar(const Samples& s, bool v_first, size_t stride) {
  PlaneBytes y{{}, stride}, c{{}, stride};
  for (int r = 0; r < kH; ++r) y.add_row(std::vector<uint8_t>(s.y.begin() + r * kW, s.y.begin() + (r + 1) * kW));
  for (int r = 0; r < kH; r += s.vertical) {
    std::vector<uint8_t> row;
    for (int i = 0; i < kW / 2; ++i) {
      row.push_back(v_first ? s.V(i, r) : s.U(i, r));
      row.push_back(v_first ? s.U(i, r) : s.V(i, r));
    }
    c.add_row(row);
  }
  return {y, c};
}

std::vector<PlaneBytes> planar(const Samples& s, size_t stride) {
  PlaneBytes y{{}, stride}, u{{}, stride / 2}, v{{}, stride / 2};
  for (int r = 0; r < kH; ++r) y.add_row(std::vector<uint8_t>(s.y.begin() + r * kW, s.y.begin() + (r + 1) * kW));
  for (int r = 0; r < kH / 2; ++r) {
    u.add_row(std::vector<uint8_t>(s.u.begin() + r * kW / 2, s.u.begin() + (r + 1) * kW / 2));
    v.add_row(std::vector<uint8_t>(s.v.begin() + r * kW / 2, s.v.begin() + (r + 1) * kW / 2));
  }
  return {y, u, v};
}

// Contiguous formats: the planes one after another in one buffer, the first plane's stride for all
// (halved for a planar format's chroma), as V4L2 defines NV12, NV21, NV16 and YUV420.
PlaneBytes contiguous(const std::vector<PlaneBytes>& planes) {
  PlaneBytes one{{}, planes[0].stride};
  for (const auto& p : planes) one.bytes.insert(one.bytes.end(), p.bytes.begin(), p.bytes.end());
  return one;
}

TEST(V4L2FrameLayout, FourTwoZeroFormatsBecomeNv12ContiguousOrSplit) {
  const Samples s = random_samples(2, 2);
  const std::vector<uint8_t> nv12 = nv12_of(s);
  const size_t stride = kW + 10;  // even: YUV420's chroma stride is half of it
  EXPECT_EQ(fill(V4L2_PIX_FMT_NV21, {contiguous(semi_planar(s, true, stride))}).data, nv12);
  EXPECT_EQ(fill(V4L2_PIX_FMT_YUV420, {contiguous(planar(s, stride))}).data, nv12);
  EXPECT_EQ(fill(V4L2_PIX_FMT_NV12M, semi_planar(s, false, stride)).data, nv12);
  EXPECT_EQ(fill(V4L2_PIX_FMT_NV21M, semi_planar(s, true, stride)).data, nv12);
  const Frame split = fill(V4L2_PIX_FMT_YUV420M, planar(s, stride));
  EXPECT_EQ(split.data, nv12);
  EXPECT_EQ(split.format, PixelFormat::NV12);
  EXPECT_EQ(split.bytes_per_line, size_t(kW));
}

TEST(V4L2FrameLayout, FourTwoTwoSemiPlanarBecomesYuyv) {
  const Samples s = random_samples(1, 3);
  EXPECT_EQ(fill(V4L2_PIX_FMT_NV16, {contiguous(semi_planar(s, false, kW + 2))}).data, yuyv_of(s));
  EXPECT_EQ(fill(V4L2_PIX_FMT_NV16M, semi_planar(s, false, kW + 4)).data, yuyv_of(s));
}

TEST(V4L2FrameLayout, TheFrameKeepsItsMemoryAndAShortPlaneIsRefused) {
  const Samples s = random_samples(2, 4);
  std::vector<PlaneBytes> planes = semi_planar(s, false, kW);
  std::vector<V4L2Plane> in;
  for (const auto& p : planes) in.push_back({p.bytes.data(), p.bytes.size(), p.stride});
  Frame frame;
  bool allocated = true;
  std::string why;
  ASSERT_TRUE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), in, kW, kH, frame, allocated, why)) << why;
  const uint8_t* memory = frame.data.data();
  ASSERT_TRUE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), in, kW, kH, frame, allocated, why)) << why;
  EXPECT_FALSE(allocated);
  EXPECT_EQ(frame.data.data(), memory);

  // The chroma plane one byte short of its last row: refused, the frame as it was.
  in[1].bytes_used -= 1;
  const std::vector<uint8_t> before = frame.data;
  EXPECT_FALSE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), in, kW, kH, frame, allocated, why));
  EXPECT_EQ(why, "plane 1: 417 bytes (stride 38), its 11 rows of 38 need 418");
  EXPECT_EQ(frame.data, before);
  // A stride smaller than a row, and the wrong number of planes.
  in[1].bytes_used += 1;
  in[0].bytes_per_line = kW - 2;
  EXPECT_FALSE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), in, kW, kH, frame, allocated, why));
  EXPECT_FALSE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), std::span(in).first(1), kW, kH, frame, allocated, why));
  EXPECT_EQ(why, "1 planes for a 2-plane format");
  // An odd width cannot hold 4:2:0 chroma pairs.
  in[0].bytes_per_line = kW;
  EXPECT_FALSE(fill_frame_from_v4l2(layout(V4L2_PIX_FMT_NV12M), in, kW - 1, kH, frame, allocated, why));
}

TEST(V4L2FrameLayout, ConfigNamesMapToTheirFourccsAndBack) {
  for (const auto& choice : kCaptureFormatNames) {
    if (choice.value == CaptureFormat::Auto || choice.value == CaptureFormat::MJPG) continue;
    const uint32_t fourcc = capture_format_fourcc(choice.value);
    ASSERT_NE(fourcc, 0u) << choice.name;
    const auto l = v4l2_frame_layout(fourcc);
    ASSERT_TRUE(l.has_value()) << choice.name;
    EXPECT_EQ(l->name, choice.value) << choice.name;
  }
  EXPECT_EQ(capture_format_fourcc(CaptureFormat::MJPG), uint32_t(V4L2_PIX_FMT_MJPEG));
  EXPECT_FALSE(v4l2_frame_layout(V4L2_PIX_FMT_MJPEG).has_value());
}

}  // namespace
}  // namespace arpipe
