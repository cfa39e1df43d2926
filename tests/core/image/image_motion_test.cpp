// patch_motion against patches rendered analytically at a known sub-pixel motion (no resampling):
// the affine fit's corner displacement, and what it leaves when something else changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "core/image/image_motion.h"

namespace arpipe {
namespace {

constexpr int kSize = 96;

// A textured patch (tag-like edges softened over about a pixel, plus smooth shading) seen through
// a motion: the value at x is the pattern at where(x).
std::vector<uint8_t> render(const std::function<std::array<double, 2>(double, double)>& where, double gain = 1.0,
                            double noise = 0.0, unsigned seed = 1) {
  std::mt19937 random(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<uint8_t> patch(size_t(kSize) * kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const auto [u, v] = where(x, y);
      // Blocks of 12 px with edges a logistic step of ~0.7 px, and a slow ramp.
      const double bx = std::sin(u * M_PI / 12.0), by = std::sin(v * M_PI / 12.0);
      const double block = 1.0 / (1.0 + std::exp(-4.0 * bx * by * 12.0 / M_PI));
      const double value = gain * (40.0 + 160.0 * block + 0.2 * u) + noise * gauss(random);
      patch[size_t(y) * kSize + size_t(x)] = uint8_t(std::clamp(std::lround(value), 0L, 255L));
    }
  return patch;
}

std::array<double, 2> shifted(double x, double y, double dx, double dy) { return {x - dx, y - dy}; }

PatchMotion motion_between(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  const auto m = patch_motion(a.data(), kSize, b.data(), kSize, kSize, kSize);
  EXPECT_TRUE(m);
  // The reference smoothed once (as the tracker keeps a still camera's) gives the same fit, to the bit.
  const auto kept = patch_motion(smoothed_patch(a.data(), kSize, kSize, kSize), b.data(), kSize);
  EXPECT_EQ(kept.has_value(), m.has_value());
  if (kept && m) {
    EXPECT_EQ(kept->max_corner_px, m->max_corner_px);
    EXPECT_EQ(kept->outlier_fraction, m->outlier_fraction);
    EXPECT_EQ(kept->gain, m->gain);
    EXPECT_EQ(kept->offset, m->offset);
  }
  return m.value_or(PatchMotion{1e9, 1});
}

TEST(PatchMotion, MeasuresSubPixelShiftsAndRotations) {
  const auto still = render([](double x, double y) { return std::array<double, 2>{x, y}; });
  for (const double shift : {0.02, 0.05, 0.1, 0.3}) {
    const auto moved = render([&](double x, double y) { return shifted(x, y, shift, -0.5 * shift); });
    const double truth = std::hypot(shift, 0.5 * shift);
    // The edges here are sharper than a pixel: even smoothed, their slope reads a little low, so
    // the motion reads high (1.11-1.13x here), the safe side for telling a still camera.
    const double measured = motion_between(still, moved).max_corner_px;
    EXPECT_GE(measured, 0.95 * truth) << shift;
    EXPECT_LE(measured, 1.2 * truth + 0.003) << shift;
  }
  // A turn of 0.002 rad about the centre moves the corners by 0.002 * 67 px = 0.13 px.
  const double angle = 0.002, c = 0.5 * (kSize - 1);
  const auto turned = render([&](double x, double y) {
    return std::array<double, 2>{c + std::cos(angle) * (x - c) + std::sin(angle) * (y - c),
                                 c - std::sin(angle) * (x - c) + std::cos(angle) * (y - c)};
  });
  const double measured = motion_between(still, turned).max_corner_px, truth = angle * std::hypot(c, c);
  EXPECT_GE(measured, 0.95 * truth);
  EXPECT_LE(measured, 1.2 * truth + 0.003);
}

TEST(PatchMotion, SensorNoiseAndExposureAreNotMotion) {
  const auto identity = [](double x, double y) { return std::array<double, 2>{x, y}; };
  const auto a = render(identity, 1.0, 2.0, 1);
  const auto b = render(identity, 1.05, 2.0, 2);  // 5 % brighter, fresh noise
  const PatchMotion m = motion_between(a, b);
  EXPECT_LT(m.max_corner_px, 0.01);
  EXPECT_LT(m.outlier_fraction, 0.005);
}

TEST(PatchMotion, AnOccluderOrALargeMotionLeavesOutliers) {
  const auto identity = [](double x, double y) { return std::array<double, 2>{x, y}; };
  const auto a = render(identity, 1.0, 2.0, 1);
  auto b = render(identity, 1.0, 2.0, 2);
  for (int y = 30; y < 50; ++y)
    for (int x = 40; x < 60; ++x) b[size_t(y) * kSize + size_t(x)] = 0;  // a finger over the patch
  EXPECT_GT(motion_between(a, b).outlier_fraction, 0.02);
  const auto far = render([](double x, double y) { return shifted(x, y, 4.0, 0.0); }, 1.0, 2.0, 3);
  const PatchMotion large = motion_between(a, far);
  EXPECT_TRUE(large.outlier_fraction > 0.02 || large.max_corner_px > 1.0);
}

// A picture whose texture is gone fits "still" with a gain of -1: the gain says so.
TEST(PatchMotion, ATextureThatVanishedShowsAsAGainOfMinusOne) {
  const auto a = render([](double x, double y) { return std::array<double, 2>{x, y}; });
  const std::vector<uint8_t> flat(a.size(), 128);
  const PatchMotion m = motion_between(a, flat);
  EXPECT_NEAR(m.gain, -1.0, 0.01);
  EXPECT_NEAR(m.offset, 128.0, 1.0);
  // And a true exposure change is that change.
  const auto brighter = render([](double x, double y) { return std::array<double, 2>{x, y}; }, 1.05);
  EXPECT_NEAR(motion_between(a, brighter).gain, 0.05, 0.01);
}

TEST(PatchMotion, AFlatPatchOrATinyOneSaysNothing) {
  const std::vector<uint8_t> flat(size_t(kSize) * kSize, 100);
  EXPECT_FALSE(patch_motion(flat.data(), kSize, flat.data(), kSize, kSize, kSize));
  EXPECT_FALSE(patch_motion(flat.data(), kSize, flat.data(), kSize, 4, 4));
}

}  // namespace
}  // namespace arpipe
