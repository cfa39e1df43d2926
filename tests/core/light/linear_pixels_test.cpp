// decode_linear_pixels against decode_linear_patch of the whole frame, and the ground ring that
// uses it (core/light/linear_patch.h, core/light/ground_radiance.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/image/camera_response.h"
#include "core/image/pixel_convert.h"
#include "core/light/ground_radiance.h"
#include "core/light/linear_patch.h"

namespace arpipe {
namespace {

Frame noise_frame(PixelFormat format, int width, int height) {
  std::vector<uint8_t> rgb(size_t(width * height * 3));
  std::mt19937 rng(11);
  for (auto& v : rgb) v = uint8_t(rng() % 256);
  Frame frame = from_rgb24(rgb.data(), width, height, format);
  frame.meta.exposure_ns = 4'000'000;
  frame.meta.analogue_gain = 2;
  return frame;
}

// Scattered pixels, odd and even columns and rows, the frame's corners among them: each is decoded
// to exactly (bit for bit) what the whole frame's patch holds there, clipped flag included.
TEST(LinearPixels, EachPixelIsWhatTheWholeFramesPatchHoldsThere) {
  const int w = 64, h = 48;
  const CameraResponse response;
  for (PixelFormat format : {PixelFormat::RGB24, PixelFormat::YUYV, PixelFormat::NV12, PixelFormat::GREY,
                             PixelFormat::SRGGB8, PixelFormat::SGBRG10P}) {
    const Frame frame = noise_frame(format, w, h);
    LinearPatch whole;
    ASSERT_TRUE(decode_linear_patch(frame, {0, 0, w, h}, response, whole)) << pixel_format_name(format);
    std::vector<LinearPixel> pixels;
    std::mt19937 rng(3);
    for (int i = 0; i < 60; ++i) pixels.push_back({int(rng() % w), int(rng() % h)});
    for (const auto& [x, y] : {std::pair{0, 0}, {w - 1, 0}, {0, h - 1}, {w - 1, h - 1}, {1, 1}, {w - 2, h - 2}})
      pixels.push_back({x, y});
    ASSERT_TRUE(decode_linear_pixels(frame, pixels, response)) << pixel_format_name(format);
    int clipped = 0;
    for (const LinearPixel& p : pixels) {
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(p.rgb[c], whole.at(p.x, p.y)[c]) << pixel_format_name(format) << " " << p.x << "," << p.y;
      ASSERT_EQ(p.clipped, whole.clipped_at(p.x, p.y)) << pixel_format_name(format) << " " << p.x << "," << p.y;
      clipped += p.clipped;
    }
    if (format == PixelFormat::RGB24) {
      EXPECT_GT(clipped, 0) << "noise this bright clips some pixels";
    }
  }
}

TEST(LinearPixels, APixelOutsideTheFrameOrAFrameWithoutExposureIsRefused) {
  const CameraResponse response;
  for (PixelFormat format : {PixelFormat::YUYV, PixelFormat::SRGGB8}) {
    Frame frame = noise_frame(format, 32, 16);
    std::vector<LinearPixel> outside{{5, 5}, {32, 3}};
    EXPECT_FALSE(decode_linear_pixels(frame, outside, response)) << pixel_format_name(format);
    std::vector<LinearPixel> above{{-1, 0}};
    EXPECT_FALSE(decode_linear_pixels(frame, above, response)) << pixel_format_name(format);
    std::vector<LinearPixel> inside{{5, 5}};
    EXPECT_TRUE(decode_linear_pixels(frame, inside, response)) << pixel_format_name(format);
    frame.meta.exposure_ns = 0;
    EXPECT_FALSE(decode_linear_pixels(frame, inside, response)) << pixel_format_name(format);
    EXPECT_FALSE(decode_linear_pixels(frame, std::span<LinearPixel>{}, response)) << "no pixels, still checked";
  }
}

// A camera 0.6 m over the anchor, looking straight down, sees the whole ring (radii 9 to 25 cm) on
// a uniform ground: the median is that ground's scene-linear value, response(v) / (exposure x
// gain), bit for bit.
TEST(GroundRadiance, AUniformGroundGivesItsOwnLinearValue) {
  const int w = 640, h = 480;
  const CameraModel camera = CameraModel::pinhole(500, 500, 319.5, 239.5, w, h);
  // Camera looking down: camera z = -world z, camera x = world x, camera y = -world y.
  const SE3 T_cam_world(Mat3{{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}, Vec3{0, 0, 0.6});
  const CameraResponse response;
  for (PixelFormat format : {PixelFormat::RGB24, PixelFormat::YUYV}) {
    const uint8_t value = 120;
    std::vector<uint8_t> rgb(size_t(w * h * 3), value);
    Frame frame = from_rgb24(rgb.data(), w, h, format);
    frame.meta.exposure_ns = 10'000'000;
    frame.meta.analogue_gain = 1;
    LinearPatch reference;
    ASSERT_TRUE(decode_linear_patch(frame, {100, 100, 2, 1}, response, reference));
    GroundRadiance ground;
    const std::optional<Vec3> measured = ground.measure(frame, camera, T_cam_world, response);
    ASSERT_TRUE(measured) << pixel_format_name(format);
    for (int c = 0; c < 3; ++c) EXPECT_EQ((*measured)[c], double(reference.at(100, 100)[c])) << pixel_format_name(format);
  }
}

}  // namespace
}  // namespace arpipe
