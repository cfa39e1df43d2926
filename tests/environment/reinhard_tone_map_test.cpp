// Reinhard's global operator (seed 002) against its formula worked by hand, and the adaptive
// luminance's time constant.
#include "core/image/reinhard_tone_map.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arpipe {
namespace {

HdrImage grey_image(std::initializer_list<float> values) {
  HdrImage image;
  image.width = int(values.size());
  image.height = 1;
  for (float v : values) image.rgb.insert(image.rgb.end(), {v, v, v});
  return image;
}

TEST(ReinhardToneMap, LogAverageIsTheGeometricMeanOfLuminance) {
  // Grey pixels: luminance = value (the weights sum to 1). exp(mean(log(delta + L))).
  const HdrImage image = grey_image({1.0f, 4.0f, 16.0f});
  const double expected = std::exp((std::log(1.0001) + std::log(4.0001) + std::log(16.0001)) / 3);
  EXPECT_NEAR(log_average_luminance(image), expected, 1e-12);
}

TEST(ReinhardToneMap, MapsLuminanceThroughKeyOverLogAverageThenXOverOnePlusX) {
  HdrImage image = grey_image({1.0f, 4.0f, 16.0f});
  const double log_average = log_average_luminance(image);
  reinhard_tone_map(image);
  for (int x = 0; x < 3; ++x) {
    const double l = std::pow(4.0, x);
    const double scaled = 0.72 / (log_average + 1e-4) * l;
    // Float storage: 1e-6.
    EXPECT_NEAR(image.rgb[3 * x], scaled / (1 + scaled), 1e-6);
  }
  // Luminance mapping keeps hue: a colour keeps its channel ratios.
  HdrImage colour;
  colour.width = colour.height = 1;
  colour.rgb = {2.0f, 1.0f, 0.5f};
  reinhard_tone_map(colour, {}, 1.0);
  EXPECT_NEAR(colour.rgb[0] / colour.rgb[1], 2.0, 1e-5);
  EXPECT_NEAR(colour.rgb[2] / colour.rgb[1], 0.5, 1e-5);
  EXPECT_LT(colour.rgb[0], 1.0f);
}

TEST(ReinhardToneMap, BlackStaysBlackAndNothingExceedsOne) {
  HdrImage image = grey_image({0.0f, 1e-30f, 1e30f});
  reinhard_tone_map(image);
  EXPECT_EQ(image.rgb[0], 0.0f);
  for (float v : image.rgb) {
    EXPECT_TRUE(std::isfinite(v));
    EXPECT_LE(v, 1.0f);
  }
}

TEST(AdaptiveLuminance, MovesByOneMinusPoint98ToTheSixtyDtEachUpdate) {
  AdaptiveLuminance adapt;
  EXPECT_EQ(adapt.update(1.0, 0.0), 1.0);  // the first value is taken as it is
  // One 60 Hz frame: 1 - 0.98 = 2 % of the way; one second: 1 - 0.98^60 = 70.2 %.
  EXPECT_NEAR(adapt.update(2.0, 1.0 / 60), 1.02, 1e-12);
  AdaptiveLuminance second;
  second.update(0.0, 0);
  EXPECT_NEAR(second.update(1.0, 1.0), 1 - std::pow(0.98, 60), 1e-12);
}

}  // namespace
}  // namespace arpipe
