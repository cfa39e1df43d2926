// How raw Bayer frames leave the source (capture/raw_colour_source.h): [source.raw] over what the
// camera said, grey-world gains measured when nobody says them, and values that cannot develop the
// frame left out. The frames are flat colours whose codes are exact: black 63 and white 1023 at
// 10 bits leave 960 codes, so linear 0.2, 0.4 and 0.1 are the codes 255, 447 and 159, and the
// grey-world gains that make them equal are exactly 2, 1 and 4 (up to float rounding, 1e-6).
#include <gtest/gtest.h>

#include <memory>

#include "capture/raw_colour_source.h"
#include "core/image/bayer.h"
#include "core/image/pixel_convert.h"
#include "core/image/srgb.h"

namespace arpipe {
namespace {

constexpr int kSize = 16;
constexpr double kBlack = 63;

// A 16x16 SGRBG10 frame of one linear colour, coded between `black` and the top code 1023.
Frame flat_frame(const std::array<double, 3>& rgb, double black = kBlack) {
  BayerMosaic mosaic;
  mosaic.width = mosaic.height = kSize;
  mosaic.order = BayerOrder::GRBG;
  mosaic.bit_depth = 10;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      mosaic.values.push_back(uint16_t(std::lround(black + rgb[size_t(mosaic.channel_at(x, y))] * (1023 - black))));
  return pack_bayer(mosaic, PixelFormat::SGRBG10);
}

constexpr std::array<double, 3> kColour{0.2, 0.4, 0.1};

void expect_gains(const RawColour& raw, const std::array<double, 3>& expected) {
  ASSERT_TRUE(raw.gains.has_value());
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR((*raw.gains)[c], expected[c], 1e-6) << "channel " << c;
}

Frame resolved(Frame frame, const RawColourConfig& config = {}) {
  RawColourResolver(config).resolve(frame);
  return frame;
}

TEST(RawColourSource, GreyWorldGainsAreMeasuredWhenNobodySaysThemAndTheFrameComesOutGrey) {
  Frame frame = flat_frame(kColour);
  frame.meta.raw.black_level = std::array<double, 4>{kBlack, kBlack, kBlack, kBlack};  // the camera says only this
  frame = resolved(frame);
  expect_gains(frame.meta.raw, {2, 1, 4});
  // Every stage develops with those gains: the colour comes out neutral, sRGB(0.4) on every channel.
  std::vector<uint8_t> rgb;
  to_rgb24(frame, rgb);
  const double grey = srgb_encode(0.4) * 255;
  for (size_t i = 0; i < rgb.size(); ++i) ASSERT_NEAR(rgb[i], grey, 0.5 + 1e-9) << "byte " << i;
}

TEST(RawColourSource, TheCamerasGainsAreKeptUnlessTheConfigSaysOtherwise) {
  Frame frame = flat_frame(kColour);
  frame.meta.raw.black_level = std::array<double, 4>{kBlack, kBlack, kBlack, kBlack};
  frame.meta.raw.gains = std::array<double, 3>{1.5, 1, 2};
  expect_gains(resolved(frame).meta.raw, {1.5, 1, 2});
  RawColourConfig config;
  config.white_balance = WhiteBalanceMode::GreyWorld;
  expect_gains(resolved(frame, config).meta.raw, {2, 1, 4});
  config.white_balance = WhiteBalanceMode::Fixed;
  config.gains = {1.25, 1, 3};
  expect_gains(resolved(frame, config).meta.raw, {1.25, 1, 3});
}

// The configured black level is the one the gains are measured with: with the camera's 0 the
// codes 255 : 447 : 159 would give 447/255 = 1.75 for red, not 2.
TEST(RawColourSource, TheConfiguredBlackLevelAndMatrixOverrideTheCamerasValues) {
  Frame frame = flat_frame(kColour);
  frame.meta.raw.black_level = std::array<double, 4>{0, 0, 0, 0};
  const std::array<double, 9> matrix{1.5, -0.25, -0.25, -0.125, 1.25, -0.125, 0, -0.5, 1.5};
  frame.meta.raw.colour_matrix = std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1};
  RawColourConfig config;
  config.black_level = {kBlack};
  config.colour_matrix.assign(matrix.begin(), matrix.end());
  const RawColour raw = resolved(frame, config).meta.raw;
  EXPECT_EQ(raw.black_level, (std::array<double, 4>{kBlack, kBlack, kBlack, kBlack}));
  EXPECT_EQ(raw.colour_matrix, matrix);
  expect_gains(raw, {2, 1, 4});
  config.black_level = {kBlack, kBlack + 1, kBlack + 2, kBlack + 3};
  EXPECT_EQ(resolved(frame, config).meta.raw.black_level, (std::array<double, 4>{kBlack, kBlack + 1, kBlack + 2, kBlack + 3}));
}

// A camera value that cannot develop a 10-bit frame is left out; a configured one is not applied
// (the camera's stays). Either way the frame still develops, and no stage throws on it.
TEST(RawColourSource, ValuesThatCannotDevelopTheFrameAreLeftOut) {
  Frame frame = flat_frame(kColour);
  frame.meta.raw.black_level = std::array<double, 4>{2000, 2000, 2000, 2000};  // above 10 bits' 1023
  frame.meta.raw.gains = std::array<double, 3>{1, -1, 1};
  RawColour raw = resolved(frame).meta.raw;
  EXPECT_FALSE(raw.black_level.has_value());
  EXPECT_EQ(raw_colour_problem(raw, frame.format), "");
  ASSERT_TRUE(raw.gains.has_value());  // measured instead of the camera's negative gain

  frame.meta.raw = RawColour{};
  frame.meta.raw.black_level = std::array<double, 4>{kBlack, kBlack, kBlack, kBlack};
  RawColourConfig config;
  config.black_level = {1023};  // not below the white level at 10 bits
  raw = resolved(frame, config).meta.raw;
  EXPECT_EQ(raw.black_level, (std::array<double, 4>{kBlack, kBlack, kBlack, kBlack}));
  expect_gains(raw, {2, 1, 4});
  std::vector<uint8_t> rgb;
  EXPECT_NO_THROW(to_rgb24(frame, rgb));
}

TEST(RawColourSource, OtherFormatsPassUntouched) {
  Frame frame = Frame::allocate(PixelFormat::RGB24, 4, 2);
  frame.data.assign(frame.data.size(), 77);
  RawColourConfig config;
  config.black_level = {64};
  config.white_balance = WhiteBalanceMode::Fixed;
  config.gains = {2, 1, 2};
  const Frame out = resolved(frame, config);
  EXPECT_EQ(out.meta.raw, RawColour{});
  EXPECT_EQ(out.data, frame.data);
}

// The decorator resolves what its inner source gives and passes everything else through.
TEST(RawColourSource, WrapsASourceFrameByFrame) {
  class OneFrame final : public FrameSource {
   public:
    std::string describe() const override { return "one flat frame"; }
    bool is_live() const override { return true; }
    std::shared_ptr<const CameraModel> camera_model() const override { return nullptr; }
    std::optional<int64_t> frame_interval_ns() const override { return 33'000'000; }
    SourceStatus next(Frame& frame) override {
      if (given_) return SourceStatus::EndOfStream;
      given_ = true;
      frame = flat_frame(kColour);
      return SourceStatus::Frame;
    }
    std::optional<CaptureCounts> capture_counts() const override { return CaptureCounts{1, 1, 0}; }

   private:
    bool given_ = false;
  };
  RawColourConfig config;
  config.black_level = {kBlack};
  RawColourSource source(std::make_unique<OneFrame>(), config);
  EXPECT_EQ(source.describe(), "one flat frame");
  EXPECT_TRUE(source.is_live());
  EXPECT_EQ(source.frame_interval_ns(), 33'000'000);
  EXPECT_EQ(source.capture_counts()->copies, 1u);
  Frame frame;
  ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  expect_gains(frame.meta.raw, {2, 1, 4});
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

}  // namespace
}  // namespace arpipe
