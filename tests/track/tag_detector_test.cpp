// Tests of TagDetector (families by name, settings, corner order and pixel convention) and of
// TagCornerRefiner, on tags rendered here with exact geometry, area sampling and an sRGB response.
#include "core/track/tag_detector.h"

#include <apriltag/apriltag.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/track/tag_corner_refiner.h"
#include "core/track/tag_family.h"

namespace arpipe {
namespace {

// A grey image (with a padded stride) of tag 0 of tag36h11 turned by `angle` about its centre, its
// code cells `cell_px` wide, in mrcal's pixel convention (pixel centres at integers). Reflectances
// are averaged over each pixel's area in linear light and then sRGB-encoded, like a camera.
struct RenderedTag {
  int width = 0, height = 0;
  size_t stride = 0;
  std::vector<uint8_t> pixels;
  std::array<Vec2, 4> corners;  // of the black border, AprilTag order: BL, BR, TR, TL
};

RenderedTag render_tag36h11(Vec2 centre, double cell_px, double angle) {
  apriltag_family_t* family = tag36h11_create();
  image_u8_t* code = apriltag_to_image(family, 0);
  RenderedTag out;
  out.width = 320, out.height = 240, out.stride = 352;
  out.pixels.assign(out.stride * out.height, 0);
  const double c = std::cos(angle), s = std::sin(angle);
  const double half = code->width * cell_px / 2;  // the printed square with its white border
  auto reflectance = [&](double x, double y) {
    // Into the tag's own axes (u right, v down as printed), origin at the printed square's corner.
    const double dx = x - centre[0], dy = y - centre[1];
    const double u = c * dx + s * dy + half, v = -s * dx + c * dy + half;
    const int col = static_cast<int>(std::floor(u / cell_px)), row = static_cast<int>(std::floor(v / cell_px));
    if (col < 0 || row < 0 || col >= code->width || row >= code->height) return 0.42;
    return code->buf[row * code->stride + col] ? 0.80 : 0.025;
  };
  // Cells are far wider than a pixel, so a pixel whose corners agree is uniform. Edge pixels take
  // 32x32 samples: an axis-aligned edge then moves in steps of 1/32 px, far below what is checked.
  constexpr int kSamples = 32;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const double first = reflectance(x - 0.5, y - 0.5);
      double linear = first;
      if (reflectance(x + 0.5, y - 0.5) != first || reflectance(x - 0.5, y + 0.5) != first ||
          reflectance(x + 0.5, y + 0.5) != first) {
        double sum = 0;
        for (int j = 0; j < kSamples; ++j)
          for (int i = 0; i < kSamples; ++i) sum += reflectance(x - 0.5 + (i + 0.5) / kSamples, y - 0.5 + (j + 0.5) / kSamples);
        linear = sum / (kSamples * kSamples);
      }
      const double encoded = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
      out.pixels[static_cast<size_t>(y) * out.stride + x] = static_cast<uint8_t>(std::lround(255 * encoded));
    }
  }
  // The detected square is the black border's outer edge: one white cell in from the printed edge.
  const double b = half - cell_px;
  const std::array<Vec2, 4> local{Vec2{-b, b}, Vec2{b, b}, Vec2{b, -b}, Vec2{-b, -b}};  // u right, v down
  for (size_t k = 0; k < 4; ++k) {
    out.corners[k] = {centre[0] + c * local[k][0] - s * local[k][1], centre[1] + s * local[k][0] + c * local[k][1]};
  }
  image_u8_destroy(code);
  tag36h11_destroy(family);
  return out;
}

double distance(const Vec2& a, const Vec2& b) { return norm(Vec2{a[0] - b[0], a[1] - b[1]}); }

struct Placement {
  Vec2 centre;
  double cell_px;
  double angle;
};
constexpr Placement kPlacements[] = {
    {{160.0, 120.0}, 12.0, 0.0},   {{151.3, 117.8}, 11.37, 0.0},  {{170.6, 110.2}, 14.1, 0.31},
    {{140.2, 131.7}, 9.6, -0.77},  {{165.9, 121.4}, 10.3, 2.2},   {{158.1, 119.3}, 15.55, -2.9},
};

TEST(TagDetector, CornersComeInAprilTagOrderWithPixelCentresAtIntegers) {
  TagDetector detector(Config{});
  for (const Placement& placement : kPlacements) {
    const RenderedTag tag = render_tag36h11(placement.centre, placement.cell_px, placement.angle);
    std::vector<TagObservation> found;
    detector.detect(tag.pixels.data(), tag.width, tag.height, tag.stride, found);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].id, 0);
    EXPECT_EQ(found[0].hamming, 0);
    // libapriltag 3.3 lands 0.1-0.5 px inside a gamma-encoded edge (see tag_corner_refiner.h); a
    // wrong corner order would be off by a whole tag side (60 px or more).
    Vec2 centroid_error{0, 0};
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_LT(distance(found[0].corners[k], tag.corners[k]), 0.6) << "corner " << k;
      centroid_error[0] += (found[0].corners[k][0] - tag.corners[k][0]) / 4;
      centroid_error[1] += (found[0].corners[k][1] - tag.corners[k][1]) / 4;
    }
    // That inward bias cancels in the centroid; a half-pixel convention error (libapriltag puts
    // pixel centres at +0.5) would not: it would show as 0.7 px here.
    EXPECT_LT(norm(centroid_error), 0.15);
  }
}

TEST(TagCornerRefiner, PutsCornersOnTheTrueEdgesWithinAFewHundredthsOfAPixel) {
  TagDetector detector(Config{});
  const TagCornerRefiner refiner(PixelFormat::GREY);
  const CameraModel camera = CameraModel::pinhole(300, 300, 159.5, 119.5, 320, 240);
  for (const Placement& placement : kPlacements) {
    const RenderedTag tag = render_tag36h11(placement.centre, placement.cell_px, placement.angle);
    std::vector<TagObservation> found;
    detector.detect(tag.pixels.data(), tag.width, tag.height, tag.stride, found);
    ASSERT_EQ(found.size(), 1u);
    std::array<Vec2, 4> corners = found[0].corners;
    ASSERT_TRUE(refiner.refine(tag.pixels.data(), tag.width, tag.height, tag.stride, camera, detector.border_cells(),
                               corners));
    // Noise-free, exact renders: what is left is bilinear interpolation of the area-sampled edge
    // profile, a few hundredths of a pixel.
    for (size_t k = 0; k < 4; ++k) EXPECT_LT(distance(corners[k], tag.corners[k]), 0.05) << "corner " << k;
  }
}

TEST(TagCornerRefiner, IgnoresASmudgeOnPartOfAnEdge) {
  const TagCornerRefiner refiner(PixelFormat::GREY);
  const CameraModel camera = CameraModel::pinhole(300, 300, 159.5, 119.5, 320, 240);
  RenderedTag tag = render_tag36h11({160.3, 119.6}, 12.0, 0.2);
  // A dark smudge (3 px radius) on the white paper just outside the right edge (BR to TR), a third
  // of the way along: the profiles across it see a second dark band and misplace the edge.
  const Vec2 along{tag.corners[2][0] - tag.corners[1][0], tag.corners[2][1] - tag.corners[1][1]};
  const double length = norm(along);
  const Vec2 outward{along[1] / length, -along[0] / length};
  const Vec2 smudge{tag.corners[1][0] + along[0] / 3 + 2.5 * outward[0], tag.corners[1][1] + along[1] / 3 + 2.5 * outward[1]};
  for (int y = 0; y < tag.height; ++y) {
    for (int x = 0; x < tag.width; ++x) {
      if (std::hypot(x - smudge[0], y - smudge[1]) < 3) tag.pixels[static_cast<size_t>(y) * tag.stride + x] = 90;
    }
  }
  // Start from corners 0.3 px off, as libapriltag's are.
  std::array<Vec2, 4> corners = tag.corners;
  for (auto& corner : corners) corner = {corner[0] + 0.2, corner[1] - 0.22};
  ASSERT_TRUE(refiner.refine(tag.pixels.data(), tag.width, tag.height, tag.stride, camera, 8, corners));
  // The disturbed points are dropped from the edge's line fit; what is left is as clean as above.
  for (size_t k = 0; k < 4; ++k) EXPECT_LT(distance(corners[k], tag.corners[k]), 0.05) << "corner " << k;
}

TEST(TagCornerRefiner, LeavesTagsTooSmallToRefineAlone) {
  const TagCornerRefiner refiner(PixelFormat::GREY);
  const CameraModel camera = CameraModel::pinhole(300, 300, 159.5, 119.5, 320, 240);
  const RenderedTag tag = render_tag36h11({160, 120}, 2.5, 0.2);  // 20 px across
  std::array<Vec2, 4> corners = tag.corners;
  EXPECT_FALSE(refiner.refine(tag.pixels.data(), tag.width, tag.height, tag.stride, camera, 8, corners));
  for (size_t k = 0; k < 4; ++k) EXPECT_EQ(corners[k], tag.corners[k]);
}

TEST(TagDetector, KnowsEveryLibapriltagFamilyByName) {
  const auto names = tag_family_names();
  EXPECT_EQ(names.size(), 9u);
  for (const auto name : names) {
    Config config;
    config.track.family = std::string(name);
    config.track.max_hamming = 0;  // keeps the big families' decode tables small
    const TagDetector detector(config);
    EXPECT_EQ(detector.family(), name);
    EXPECT_GT(detector.code_count(), 0);
  }
  const TagDetector tag36h11(Config{});
  EXPECT_EQ(tag36h11.code_count(), 587);
  EXPECT_EQ(tag36h11.border_cells(), 8);
}

TEST(TagDetector, RefusesADecodeTableThatWouldNeedGigabytes) {
  Config config;
  config.file = "big.toml";
  config.track.family = "tagStandard52h13";
  config.track.max_hamming = 2;  // 67 million entries, 6 GB in libapriltag 3.3
  try {
    const TagDetector detector(config);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("big.toml: track.max_hamming"), std::string::npos) << message;
    EXPECT_NE(message.find("tagStandard52h13"), std::string::npos) << message;
  }
  config.track.family = "tag36h11";
  config.track.max_hamming = 3;  // 4.6 million entries, 1.2 GB
  EXPECT_THROW(TagDetector{config}, ConfigError);
}

TEST(TagDetector, BadImagesYieldNoTags) {
  TagDetector detector(Config{});
  std::vector<TagObservation> found{TagObservation{}};
  detector.detect(nullptr, 10, 10, 10, found);
  EXPECT_TRUE(found.empty());
  const std::vector<uint8_t> pixels(100, 255);
  found.assign(1, TagObservation{});
  detector.detect(pixels.data(), 10, 10, 5, found);  // stride shorter than a row
  EXPECT_TRUE(found.empty());
  detector.detect(pixels.data(), 10, 10, 10, found);  // blank
  EXPECT_TRUE(found.empty());
}

}  // namespace
}  // namespace arpipe
