// Raw Bayer frames: the pixel-format table against V4L2's definitions, packing against hand-made
// bytes, OpenCV's CFA naming against mosaics of known colours, black level, white balance, colour
// matrix, and the demosaicer's error on a chart with edges against the analytic bound.
#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/image/bayer.h"
#include "tests/core/image/demosaic_neighbourhood.h"
#include "core/image/pixel_convert.h"
#include "core/image/srgb.h"

namespace arpipe {
namespace {

constexpr PixelFormat kAllBayer[] = {
    PixelFormat::SRGGB8,   PixelFormat::SBGGR8,   PixelFormat::SGRBG8,   PixelFormat::SGBRG8,
    PixelFormat::SRGGB10,  PixelFormat::SBGGR10,  PixelFormat::SGRBG10,  PixelFormat::SGBRG10,
    PixelFormat::SRGGB12,  PixelFormat::SBGGR12,  PixelFormat::SGRBG12,  PixelFormat::SGBRG12,
    PixelFormat::SRGGB16,  PixelFormat::SBGGR16,  PixelFormat::SGRBG16,  PixelFormat::SGBRG16,
    PixelFormat::SRGGB10P, PixelFormat::SBGGR10P, PixelFormat::SGRBG10P, PixelFormat::SGBRG10P,
    PixelFormat::SRGGB12P, PixelFormat::SBGGR12P, PixelFormat::SGRBG12P, PixelFormat::SGBRG12P};

// A mosaic whose every pixel holds its channel of `linear` (0..1) at the format's depth.
BayerMosaic flat_mosaic(PixelFormat format, int width, int height, std::array<double, 3> linear,
                        std::array<double, 4> black = {0, 0, 0, 0}) {
  BayerMosaic m{width, height, *bayer_order(format), bayer_bit_depth(format), {}};
  const double top = double((1 << m.bit_depth) - 1);
  m.values.resize(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double b = black[size_t(m.cell_position_at(x, y))];
      m.values[size_t(y) * width + x] = uint16_t(std::lround(b + linear[size_t(m.channel_at(x, y))] * (top - b)));
    }
  return m;
}

TEST(BayerFormat, NamesFourccsOrdersAndDepthsFollowV4l2) {
  EXPECT_EQ(pixel_format_fourcc(PixelFormat::SRGGB10P), uint32_t(V4L2_PIX_FMT_SRGGB10P));
  EXPECT_EQ(pixel_format_fourcc(PixelFormat::SGRBG10), uint32_t(V4L2_PIX_FMT_SGRBG10));  // 'BA10'
  EXPECT_EQ(pixel_format_fourcc(PixelFormat::SBGGR16), uint32_t(V4L2_PIX_FMT_SBGGR16));  // 'BYR2'
  EXPECT_EQ(pixel_format_fourcc(PixelFormat::SBGGR8), uint32_t(V4L2_PIX_FMT_SBGGR8));    // 'BA81'
  for (PixelFormat f : kAllBayer) {
    EXPECT_EQ(pixel_format_from_name(pixel_format_name(f)), f);
    EXPECT_EQ(pixel_format_from_fourcc(pixel_format_fourcc(f)), f);
    const std::string name(pixel_format_name(f));
    EXPECT_EQ(name.substr(1, 4), bayer_order_name(*bayer_order(f))) << name;
    EXPECT_EQ(bayer_bit_depth(f), std::stoi(name.substr(5))) << name;
    EXPECT_EQ(is_mipi_packed(f), name.back() == 'P') << name;
  }
  EXPECT_FALSE(is_bayer(PixelFormat::GREY));
  EXPECT_EQ(bayer_order(PixelFormat::YUYV), std::nullopt);
}

TEST(BayerFormat, StridesAndSizesAreWhatThePackingNeeds) {
  EXPECT_EQ(min_bytes_per_line(PixelFormat::SRGGB8, 640), 640u);
  EXPECT_EQ(min_bytes_per_line(PixelFormat::SRGGB10, 640), 1280u);
  EXPECT_EQ(min_bytes_per_line(PixelFormat::SRGGB16, 640), 1280u);
  EXPECT_EQ(min_bytes_per_line(PixelFormat::SRGGB10P, 640), 800u);  // 4 pixels in 5 bytes
  EXPECT_EQ(min_bytes_per_line(PixelFormat::SRGGB12P, 640), 960u);  // 2 pixels in 3 bytes
  EXPECT_EQ(image_bytes(PixelFormat::SRGGB10P, 640, 480, 800), 800u * 480);
  EXPECT_EQ(check_image_size(PixelFormat::SRGGB12P, 6, 4), std::nullopt);
  EXPECT_NE(check_image_size(PixelFormat::SRGGB8, 5, 4), std::nullopt);
  EXPECT_NE(check_image_size(PixelFormat::SRGGB8, 4, 5), std::nullopt);
  EXPECT_NE(check_image_size(PixelFormat::SRGGB10P, 6, 4), std::nullopt);  // not whole 5-byte groups
}

TEST(BayerMosaicPacking, MipiPackedBytesAreV4l2s) {
  // V4L2 pixfmt-srggb10p: four high bytes, then p0's 2 low bits in bits 0-1 ... p3's in bits 6-7.
  BayerMosaic m{4, 2, BayerOrder::RGGB, 10, {0x3ff, 0x000, 0x155, 0x002, 0, 0, 0, 0}};
  Frame f = pack_bayer(m, PixelFormat::SRGGB10P);
  ASSERT_EQ(f.bytes_per_line, 5u);
  EXPECT_EQ(std::vector<uint8_t>(f.data.begin(), f.data.begin() + 5), (std::vector<uint8_t>{0xff, 0x00, 0x55, 0x00, 0x93}));
  // pixfmt-srggb12p: two high bytes, then p0's low nibble in bits 0-3 and p1's in bits 4-7.
  BayerMosaic m12{2, 2, BayerOrder::RGGB, 12, {0xabc, 0x123, 0, 0}};
  Frame f12 = pack_bayer(m12, PixelFormat::SRGGB12P);
  EXPECT_EQ(std::vector<uint8_t>(f12.data.begin(), f12.data.begin() + 3), (std::vector<uint8_t>{0xab, 0x12, 0x3c}));
  // Unpacked 10-bit: little-endian words.
  Frame f10 = pack_bayer(BayerMosaic{2, 2, BayerOrder::RGGB, 10, {0x2a5, 1, 2, 3}}, PixelFormat::SRGGB10);
  EXPECT_EQ(f10.data[0], 0xa5);
  EXPECT_EQ(f10.data[1], 0x02);
}

TEST(BayerMosaicPacking, EveryFormatRoundTripsThroughAPaddedStride) {
  std::mt19937 rng(7);
  for (PixelFormat format : kAllBayer) {
    const int bits = bayer_bit_depth(format);
    BayerMosaic m{12, 6, *bayer_order(format), bits, {}};
    for (int i = 0; i < 72; ++i) m.values.push_back(uint16_t(rng() % (1u << bits)));
    const Frame tight = pack_bayer(m, format);
    // The same rows 7 bytes further apart, padding filled with junk that must not be read.
    Frame padded = tight;
    padded.bytes_per_line = tight.bytes_per_line + 7;
    padded.data.assign(padded.bytes_per_line * 6, 0xee);
    for (int y = 0; y < 6; ++y)
      std::copy_n(tight.data.begin() + long(y * tight.bytes_per_line), tight.bytes_per_line,
                  padded.data.begin() + long(y * padded.bytes_per_line));
    BayerMosaic back;
    unpack_bayer(padded, back);
    EXPECT_EQ(back.values, m.values) << pixel_format_name(format);
    EXPECT_EQ(back.bit_depth, bits);
  }
}

TEST(BayerMosaicPacking, RefusesShortBuffersStridesAndOddSizes) {
  Frame f = pack_bayer(flat_mosaic(PixelFormat::SRGGB10P, 8, 4, {0.5, 0.5, 0.5}), PixelFormat::SRGGB10P);
  BayerMosaic out;
  Frame short_buffer = f;
  short_buffer.data.resize(f.data.size() - 1);
  EXPECT_THROW(unpack_bayer(short_buffer, out), std::invalid_argument);
  Frame narrow = f;
  narrow.bytes_per_line = 9;  // 8 pixels need 10
  EXPECT_THROW(unpack_bayer(narrow, out), std::invalid_argument);
  Frame odd = f;
  odd.height = 3;
  EXPECT_THROW(unpack_bayer(odd, out), std::invalid_argument);
  Frame not_bayer = f;
  not_bayer.format = PixelFormat::GREY;
  EXPECT_THROW(unpack_bayer(not_bayer, out), std::invalid_argument);
}

// OpenCV names patterns by the second row; each V4L2 order must still give the colour it holds.
TEST(BayerDevelop, EachCfaOrderComesBackAsTheColourItHolds) {
  const std::array<double, 3> colour{0.2, 0.5, 0.8};
  for (PixelFormat format : {PixelFormat::SRGGB16, PixelFormat::SBGGR16, PixelFormat::SGRBG16, PixelFormat::SGBRG16}) {
    const Frame f = pack_bayer(flat_mosaic(format, 16, 12, colour), format);
    std::vector<float> rgb;
    develop_bayer(f, BayerDevelopment{}, rgb);
    ASSERT_EQ(rgb.size(), 16u * 12 * 3);
    // Every pixel, borders included: a flat field is exact up to the 16-bit steps (two of them:
    // the raw code and the demosaicer's own code).
    for (size_t i = 0; i < rgb.size(); ++i) ASSERT_NEAR(rgb[i], colour[i % 3], 2.0 / 65535) << pixel_format_name(format) << " " << i;
  }
}

TEST(BayerDevelop, PerChannelBlackLevelAndWhiteLevelNormalise) {
  const std::array<double, 4> black{64, 60, 68, 72};
  const Frame f = pack_bayer(flat_mosaic(PixelFormat::SGRBG10P, 16, 8, {0.25, 0.5, 0.75}, black), PixelFormat::SGRBG10P);
  BayerDevelopment dev;
  dev.black_level = black;
  std::vector<float> rgb;
  develop_bayer(f, dev, rgb);
  // Rounding the raw code to 10 bits: half a code in (1023 - black) codes.
  for (size_t i = 0; i < rgb.size(); ++i) ASSERT_NEAR(rgb[i], (i % 3 + 1) * 0.25, 0.5 / 950 + 2.0 / 65535) << i;
  dev.white_level = 50;  // below the black level
  EXPECT_THROW(develop_bayer(f, dev, rgb), std::invalid_argument);
}

TEST(BayerDevelop, GreyWorldFindsTheGainsAndIgnoresClippedCells) {
  // A grey scene seen through a sensor 2x as sensitive in green as in red, 1.25x as in blue;
  // the top half is a blown highlight (every channel at full scale), which must not count.
  const int w = 16, h = 16;
  BayerMosaic m = flat_mosaic(PixelFormat::SRGGB12, w, h, {0.2, 0.4, 0.32});
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w; ++x) m.values[size_t(y) * w + x] = 4095;
  std::vector<float> normalised;
  normalise_bayer(m, BayerDevelopment{}, normalised);
  const std::array<double, 3> gains = grey_world_gains(normalised, w, h, m.order);
  EXPECT_NEAR(gains[0], 2.0, 1e-3);
  EXPECT_EQ(gains[1], 1.0);
  EXPECT_NEAR(gains[2], 1.25, 1e-3);
  BayerDevelopment dev;
  dev.grey_world = true;
  std::vector<float> rgb;
  develop_bayer(pack_bayer(m, PixelFormat::SRGGB12), dev, rgb);
  // Well inside the grey half (3 rows from the highlight's edge): grey at the green level.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[(size_t(13) * w + 8) * 3 + size_t(c)], 0.4, 1e-3) << c;
}

TEST(BayerDevelop, ColourMatrixMixesChannels) {
  const Frame f = pack_bayer(flat_mosaic(PixelFormat::SRGGB16, 8, 8, {0.1, 0.2, 0.4}), PixelFormat::SRGGB16);
  BayerDevelopment dev;
  dev.colour_matrix = std::array<double, 9>{0, 0, 1, 0, 1, 0, 0.5, 0.5, 0};  // swap R and B; B = (R + G) / 2
  std::vector<float> rgb;
  develop_bayer(f, dev, rgb);
  EXPECT_NEAR(rgb[0], 0.4, 1e-4);
  EXPECT_NEAR(rgb[1], 0.2, 1e-4);
  EXPECT_NEAR(rgb[2], 0.15, 1e-4);
}

TEST(BayerDevelop, FlowsThroughPixelConvertLikeAnyFormat) {
  // from_rgb24 mosaics the sRGB colour at 12 bits; to_rgb24 develops and encodes it back.
  const int w = 8, h = 6;
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = 200;
    rgb[i + 1] = 90;
    rgb[i + 2] = 30;
  }
  for (PixelFormat format : {PixelFormat::SBGGR12P, PixelFormat::SGBRG8, PixelFormat::SRGGB10}) {
    const Frame f = from_rgb24(rgb.data(), w, h, format);
    std::vector<uint8_t> back, grey;
    to_rgb24(f, back);
    // The raw code rounds the linear value by up to half a code of the format's depth, which the
    // sRGB curve magnifies (8 bits: blue 30 is linear 0.0130, 3.3 codes): that, plus the output's own
    // half-code rounding.
    const double top = double((1 << bayer_bit_depth(format)) - 1);
    for (size_t i = 0; i < back.size(); ++i) {
      const double linear = srgb_decode(rgb[i] / 255.0);
      const double tolerance = 0.5 + 255 * (srgb_encode(linear + 0.5 / top) - srgb_encode(linear));
      ASSERT_NEAR(back[i], rgb[i], tolerance) << pixel_format_name(format) << " " << i;
    }
    to_grey(f, grey);
    // to_grey is the full-range BT.601 luma of to_rgb24's colour.
    const double luma = 0.299 * back[0] + 0.587 * back[1] + 0.114 * back[2];
    for (uint8_t g : grey) ASSERT_NEAR(g, luma, 0.51) << pixel_format_name(format);
  }
}

// The demosaicer's error on a chart of 16x16 patches of distinct colours (vertical and horizontal
// edges) with a disc on top (edges at every angle). Analytic expectation:
// - where a pixel's 5x5 neighbourhood is one colour, every interpolation (the edge-aware green
//   average along the smoother direction, the red/blue colour-difference averages) sees equal
//   samples, so the answer is exact up to the 16-bit steps (2/65535);
// - elsewhere each missing value is an average of neighbours' values or of neighbours' colour
//   differences added to a green that is itself a neighbours' average, so it lies within the
//   neighbourhood's range widened by that range once more per colour-difference step (two: green
//   first, then red/blue): error <= 3 x (max - min over the 5x5 neighbourhood and all channels);
// - the mean is then at most the fraction of pixels near an edge times 3 x the chart's largest step.
TEST(BayerDevelop, DemosaicErrorOnAnEdgeChartIsWithinTheAnalyticBound) {
  const int w = 96, h = 96, radius = 2;
  auto truth = [&](int x, int y, int c) {
    const double dx = x - 47.5, dy = y - 47.5;
    if (dx * dx + dy * dy < 22.0 * 22.0) return std::array{0.85, 0.3, 0.1}[size_t(c)];
    const int patch = (y / 16) * 6 + x / 16;
    return 0.05 + 0.8 * double((patch * 7 + c * 11) % 17) / 16.0;
  };
  BayerMosaic m{w, h, BayerOrder::RGGB, 16, std::vector<uint16_t>(size_t(w) * h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.values[size_t(y) * w + x] = uint16_t(std::lround(truth(x, y, m.channel_at(x, y)) * 65535));
  std::vector<float> rgb;
  develop_bayer(pack_bayer(m, PixelFormat::SRGGB16), BayerDevelopment{}, rgb);

  double sum = 0, worst = 0, worst_flat = 0, largest_step = 0;
  size_t near_edge = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [lo, hi, flat] = test::demosaic_neighbourhood(truth, x, y, w, h, radius, 0.0);
      near_edge += flat ? 0 : 1;
      largest_step = std::max(largest_step, hi - lo);
      for (int c = 0; c < 3; ++c) {
        const double error = std::abs(rgb[(size_t(y) * w + x) * 3 + size_t(c)] - truth(x, y, c));
        sum += error;
        worst = std::max(worst, error);
        if (flat) worst_flat = std::max(worst_flat, error);
        else ASSERT_LE(error, 3 * (hi - lo)) << x << "," << y << " channel " << c;
      }
    }
  const double mean = sum / (3.0 * w * h);
  const double near_fraction = double(near_edge) / (w * h);
  std::printf("demosaic error on the edge chart: mean %.5f, max %.4f, max in flat regions %.2g (%.1f%% of pixels near an edge)\n",
              mean, worst, worst_flat, 100 * near_fraction);
  EXPECT_LE(worst_flat, 2.0 / 65535);
  EXPECT_LE(mean, near_fraction * 3 * largest_step);
}

}  // namespace
}  // namespace arpipe
