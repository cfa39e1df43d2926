// The composite's CPU arithmetic: encoding linear light to a camera's 8-bit codes (against the
// response's closed-form inverse, rounded to nearest) and the premultiplied blend (against the
// formula evaluated in double precision).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/image/premultiplied_blend.h"
#include "core/image/response_encoder.h"
#include "core/image/srgb.h"

namespace arpipe {
namespace {

// encode() in closed form: the inverse of each response's decode, in double precision.
double encoded_exactly(const CameraResponse& response, double linear) {
  switch (response.kind()) {
    case CameraResponse::Kind::Srgb: return srgb_encode(linear);
    case CameraResponse::Kind::Gamma: return std::pow(linear, 1.0 / response.gamma_value());
    case CameraResponse::Kind::Linear: break;
  }
  return linear;
}

const std::vector<CameraResponse>& responses() {
  static const std::vector<CameraResponse> all{CameraResponse::srgb(), CameraResponse::linear(),
                                               CameraResponse::gamma(2.2), CameraResponse::gamma(0.8)};
  return all;
}

TEST(ResponseEncoder, EveryCodeComesBackFromItsDecodedValue) {
  for (const CameraResponse& response : responses()) {
    const ResponseEncoder encoder(response);
    for (int code = 0; code < 256; ++code)
      EXPECT_EQ(encoder.encode(response.decode8(uint8_t(code))), code) << response.name();
  }
}

TEST(ResponseEncoder, RoundsTheClosedFormInverseToTheNearestCode) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const CameraResponse& response : responses()) {
    const ResponseEncoder encoder(response);
    int checked = 0;
    for (int i = 0; i < 200000; ++i) {
      // Uniform in linear light and, to cover the dark codes, in its square.
      const double u = uniform(random);
      const float linear = static_cast<float>(i % 2 ? u : u * u * u);
      const double exact = 255.0 * encoded_exactly(response, double(linear));
      // A value within float rounding of a half code may go either way.
      if (std::abs(exact - std::floor(exact) - 0.5) < 1e-4) continue;
      ++checked;
      ASSERT_EQ(encoder.encode(linear), int(std::lround(exact))) << response.name() << " " << linear;
    }
    EXPECT_GT(checked, 199000);
  }
  const ResponseEncoder srgb;
  EXPECT_EQ(srgb.encode(-0.5f), 0);
  EXPECT_EQ(srgb.encode(std::nanf("")), 0);
  EXPECT_EQ(srgb.encode(1.0f), 255);
  EXPECT_EQ(srgb.encode(7.0f), 255);
}

TEST(PremultipliedBlend, IsTheLayerOverTheDecodedPictureInsideTheRectangleOnly) {
  const CameraResponse srgb = CameraResponse::srgb();
  const ResponseEncoder encoder(srgb);
  const int width = 5, height = 4;
  const size_t line = width * 3 + 2;  // padded rows
  std::vector<uint8_t> picture(line * height);
  for (size_t i = 0; i < picture.size(); ++i) picture[i] = uint8_t(40 + 13 * i % 200);
  const std::vector<uint8_t> before = picture;
  const PixelRect rect{1, 1, 3, 2};
  // Per pixel of the rect: an opaque colour, a half-transparent one, a pure shadow (black, alpha
  // 0.4: the picture darkened to 0.6), nothing, and values out of range that must clamp.
  const float cases[6][4] = {{0.2f, 0.5f, 0.9f, 1.0f}, {0.1f, 0.05f, 0.3f, 0.5f}, {0, 0, 0, 0.4f},
                             {0, 0, 0, 0},            {2.0f, -1.0f, 0.5f, 0.2f}, {0.0f, 0.0f, 0.01f, 0.0f}};
  std::vector<float> layer;
  for (const auto& c : cases) layer.insert(layer.end(), c, c + 4);
  blend_premultiplied_over(layer.data(), rect, srgb, encoder, picture.data(), line);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t at = size_t(y) * line + size_t(x) * 3 + size_t(c);
        if (!rect.contains(x, y)) {
          EXPECT_EQ(picture[at], before[at]) << x << "," << y;
          continue;
        }
        const float* l = &layer[(size_t(y - rect.y) * rect.width + size_t(x - rect.x)) * 4];
        const double linear = l[c] + (1.0 - l[3]) * srgb_decode(before[at] / 255.0);
        const double expected = std::lround(255.0 * srgb_encode(std::clamp(linear, 0.0, 1.0)));
        EXPECT_EQ(double(picture[at]), expected) << x << "," << y << " channel " << c;
      }
}

}  // namespace
}  // namespace arpipe
