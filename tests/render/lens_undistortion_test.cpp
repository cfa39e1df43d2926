// Tests of the camera-frame undistortion (render.lens = "undistort") against an independent
// computation: every output pixel is the camera frame sampled bilinearly in linear light where
// mrcal projects the pinhole core's ray; black where the lens does not see; a pinhole copies.
#include "render/lens/lens_undistortion.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>

namespace arpipe {
namespace {

constexpr int kWidth = 640, kHeight = 480;

double decode(double encoded) { return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4); }
double encode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

// Smooth but different in every channel, so a slip of a pixel or a swapped axis shows.
Frame smooth_frame() {
  Frame frame = Frame::allocate(PixelFormat::RGB24, kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      uint8_t* p = frame.data.data() + size_t(y) * frame.bytes_per_line + size_t(x) * 3;
      p[0] = uint8_t(127.5 + 127 * std::sin(0.031 * x + 0.017 * y));
      p[1] = uint8_t(127.5 + 127 * std::cos(0.023 * x - 0.029 * y));
      p[2] = uint8_t((x * 255) / (kWidth - 1));
    }
  return frame;
}

const uint8_t* at(const Frame& frame, int x, int y) {
  return frame.data.data() + size_t(y) * frame.bytes_per_line + size_t(x) * 3;
}

// The reference: mrcal's projection of the core ray, bilinear in linear light (double), edge
// pixels repeated within the image's outer half pixel, black beyond.
std::array<int, 3> expected_pixel(const CameraModel& lens, const Frame& source, int x, int y) {
  const std::optional<Vec2> s = lens.project(Vec3{(x - lens.cx()) / lens.fx(), (y - lens.cy()) / lens.fy(), 1.0});
  if (!s || (*s)[0] < -0.5 || (*s)[0] > kWidth - 0.5 || (*s)[1] < -0.5 || (*s)[1] > kHeight - 0.5) return {0, 0, 0};
  const double sx = std::clamp((*s)[0], 0.0, kWidth - 1.0), sy = std::clamp((*s)[1], 0.0, kHeight - 1.0);
  const int x0 = std::min(int(sx), kWidth - 2), y0 = std::min(int(sy), kHeight - 2);
  const double fx = sx - x0, fy = sy - y0;
  std::array<int, 3> out{};
  for (size_t c = 0; c < 3; ++c) {
    const double linear = (1 - fy) * ((1 - fx) * decode(at(source, x0, y0)[c] / 255.0) +
                                      fx * decode(at(source, x0 + 1, y0)[c] / 255.0)) +
                          fy * ((1 - fx) * decode(at(source, x0, y0 + 1)[c] / 255.0) +
                                fx * decode(at(source, x0 + 1, y0 + 1)[c] / 255.0));
    out[c] = int(std::lround(255 * encode(linear)));
  }
  return out;
}

struct Counts {
  int black = 0;
  int wrong = 0;
};

Counts compare_with_reference(const CameraModel& lens) {
  const Frame source = smooth_frame();
  const LensUndistortion undistortion(lens);
  Frame out;
  const auto start = std::chrono::steady_clock::now();
  undistortion.apply(source, out);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << lens.lensmodel() << ": undistorting 640x480 took " << ms << " ms\n";
  EXPECT_EQ(out.width, kWidth);
  EXPECT_EQ(out.height, kHeight);
  Counts counts;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const std::array<int, 3> expected = expected_pixel(lens, source, x, y);
      const uint8_t* got = at(out, x, y);
      if (expected == std::array<int, 3>{0, 0, 0} && got[0] == 0 && got[1] == 0 && got[2] == 0) ++counts.black;
      for (size_t c = 0; c < 3; ++c)
        // 1 LSB: float weights and a 1/65535 linear table against double; a wrong sample
        // position on these gradients (2-3 LSB per pixel) or sRGB-space mixing is more.
        if (std::abs(got[c] - expected[c]) > 1 && ++counts.wrong <= 5)
          ADD_FAILURE() << "pixel (" << x << ", " << y << ") channel " << c << ": " << int(got[c]) << ", expected "
                        << expected[c];
    }
  return counts;
}

TEST(LensUndistortion, BarrelLensMatchesTheReference) {
  const CameraModel lens("LENSMODEL_OPENCV8", {400, 400, 322.3, 236.8, -0.30, 0.10, 0.001, -0.0008, -0.01, 0, 0, 0},
                         kWidth, kHeight);
  const Counts counts = compare_with_reference(lens);
  EXPECT_EQ(counts.wrong, 0);
  EXPECT_EQ(counts.black, 0);  // barrel: the lens sees more than its pinhole core
}

TEST(LensUndistortion, PincushionLensLeavesWhatItDoesNotSeeBlack) {
  const CameraModel lens("LENSMODEL_OPENCV4", {380, 385, 316.1, 243.7, 0.12, 0.02, -0.0005, 0.0007}, kWidth, kHeight);
  const Counts counts = compare_with_reference(lens);
  EXPECT_EQ(counts.wrong, 0);
  EXPECT_GT(counts.black, 1000);  // the core's corners lie outside the camera frame
}

TEST(LensUndistortion, PinholeLensCopiesTheBytesAndIsItsOwnCore) {
  const CameraModel lens = CameraModel::pinhole(400, 402, 320.1, 239.7, kWidth, kHeight);
  const LensUndistortion undistortion(lens);
  const Frame source = smooth_frame();
  Frame out;
  undistortion.apply(source, out);
  EXPECT_EQ(out.data, source.data);
  EXPECT_EQ(undistortion.pinhole_core()->lensmodel(), "LENSMODEL_PINHOLE");
  EXPECT_EQ(undistortion.pinhole_core()->intrinsics(), lens.intrinsics());
}

TEST(LensUndistortion, CoreIsThePinholeOfTheLensIntrinsics) {
  const CameraModel lens("LENSMODEL_OPENCV4", {380, 385, 316.1, 243.7, 0.12, 0.02, -0.0005, 0.0007}, kWidth, kHeight);
  const LensUndistortion undistortion(lens);
  const CameraModel& core = *undistortion.pinhole_core();
  EXPECT_EQ(core.lensmodel(), "LENSMODEL_PINHOLE");
  EXPECT_EQ(core.intrinsics(), (std::vector<double>{380, 385, 316.1, 243.7}));
  EXPECT_EQ(core.width(), kWidth);
  EXPECT_EQ(core.height(), kHeight);
}

}  // namespace
}  // namespace arpipe
