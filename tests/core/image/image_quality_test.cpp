// PSNR and SSIM over a mask against values worked out by hand from their definitions.
#include "core/image/image_quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arpipe {
namespace {

struct Image {
  std::vector<uint8_t> data;
  int width, height;
  RgbView view() const { return {data, width, height}; }
};

Image gradient(int width, int height) {
  Image image{std::vector<uint8_t>(size_t(width) * height * 3), width, height};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) image.data[(size_t(y) * width + x) * 3 + c] = uint8_t((7 * x + 3 * y + 40 * c) % 200 + 20);
  return image;
}

TEST(ImageQuality, IdenticalImagesScoreInfinityAndOne) {
  const Image a = gradient(40, 30);
  const std::vector<uint8_t> mask(40 * 30, 1);
  EXPECT_TRUE(std::isinf(masked_psnr(a.view(), a.view(), mask)));
  EXPECT_DOUBLE_EQ(masked_ssim(a.view(), a.view(), mask), 1.0);
}

TEST(ImageQuality, PsnrOfAConstantOffsetInTheMaskOnly) {
  const Image a = gradient(40, 30);
  Image b = a;
  std::vector<uint8_t> mask(40 * 30, 0);
  for (int i = 100; i < 400; ++i) {
    mask[size_t(i)] = 1;
    for (int c = 0; c < 3; ++c) b.data[size_t(i) * 3 + c] = uint8_t(a.data[size_t(i) * 3 + c] + 5);
  }
  for (int i = 500; i < 600; ++i) b.data[size_t(i) * 3] = 0;  // outside the mask: ignored
  // MSE = 25 in every masked sample: 10 log10(255^2 / 25) = 20 log10(51).
  EXPECT_NEAR(masked_psnr(a.view(), b.view(), mask), 20 * std::log10(51.0), 1e-12);
}

TEST(ImageQuality, SsimOfABrightnessShiftFollowsTheLuminanceTerm) {
  // y = x + d: the variances and covariance are equal, so SSIM = (2 mx my + C1)/(mx^2 + my^2 + C1)
  // per window; on a constant image that is exact for every window.
  Image a{std::vector<uint8_t>(20 * 20 * 3, 100), 20, 20};
  Image b{std::vector<uint8_t>(20 * 20 * 3, 110), 20, 20};
  const std::vector<uint8_t> mask(400, 1);
  const double c1 = (0.01 * 255) * (0.01 * 255);
  EXPECT_NEAR(masked_ssim(a.view(), b.view(), mask), (2 * 100.0 * 110.0 + c1) / (100.0 * 100.0 + 110.0 * 110.0 + c1), 1e-12);
}

TEST(ImageQuality, NoiseLowersBothMeasures) {
  const Image a = gradient(64, 48);
  Image b = a;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 4);
  for (uint8_t& v : b.data) v = uint8_t(std::clamp(v + std::lround(noise(rng)), 0L, 255L));
  const std::vector<uint8_t> mask(64 * 48, 1);
  // Gaussian noise of sigma 4 (before rounding): PSNR about 20 log10(255/4) = 36.1 dB.
  EXPECT_NEAR(masked_psnr(a.view(), b.view(), mask), 36.1, 0.5);
  const double ssim = masked_ssim(a.view(), b.view(), mask);
  EXPECT_LT(ssim, 0.99);
  EXPECT_GT(ssim, 0.5);
}

TEST(ImageQuality, EmptyMaskIsNanAndSizesAreChecked) {
  const Image a = gradient(8, 8);
  const std::vector<uint8_t> none(64, 0);
  EXPECT_TRUE(std::isnan(masked_psnr(a.view(), a.view(), none)));
  EXPECT_TRUE(std::isnan(masked_ssim(a.view(), a.view(), none)));
  const std::vector<uint8_t> wrong(10, 1);
  EXPECT_THROW(masked_psnr(a.view(), a.view(), wrong), std::invalid_argument);
}

TEST(ImageQuality, DilationGrowsASquare) {
  std::vector<uint8_t> mask(10 * 10, 0);
  mask[5 * 10 + 5] = 1;
  const std::vector<uint8_t> grown = dilate_mask(mask, 10, 10, 2);
  int count = 0;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      const bool inside = std::abs(x - 5) <= 2 && std::abs(y - 5) <= 2;
      EXPECT_EQ(bool(grown[size_t(y) * 10 + x]), inside) << x << "," << y;
      count += grown[size_t(y) * 10 + x];
    }
  EXPECT_EQ(count, 25);
}

}  // namespace
}  // namespace arpipe
