// Pixel conversion tests against the BT.601 equations evaluated in floating point (an independent
// form of the fixed-point code): known colours, round trips, layouts, strides.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/image/pixel_convert.h"

namespace arpipe {
namespace {

struct Yuv {
  double y, u, v;
};
struct Rgb {
  int r, g, b;
};

// ITU-R BT.601 studio range, from 8-bit R'G'B' (ITU-R BT.601-7, section 2.5.4 scaled to 8 bits).
Yuv bt601_encode(double r, double g, double b) {
  return {16 + (65.481 * r + 128.553 * g + 24.966 * b) / 255.0, 128 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255.0,
          128 + (112.0 * r - 93.786 * g - 18.214 * b) / 255.0};
}
// Its exact inverse, clamped to 8 bits.
Rgb bt601_decode(double y, double u, double v) {
  const double c = (y - 16) * 255.0 / 219.0, d = (u - 128) * 255.0 / 224.0, e = (v - 128) * 255.0 / 224.0;
  const auto clamp = [](double x) { return static_cast<int>(std::lround(std::clamp(x, 0.0, 255.0))); };
  return {clamp(c + 1.402 * e), clamp(c - 0.344136 * d - 0.714136 * e), clamp(c + 1.772 * d)};
}

// An image of 2x2 blocks, each one colour, so 4:2:2 and 4:2:0 subsampling lose nothing.
std::vector<uint8_t> uniform_blocks(const std::vector<Rgb>& colours, int& width, int& height) {
  width = 2 * static_cast<int>(colours.size());
  height = 2;
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (size_t k = 0; k < colours.size(); ++k)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) {
        uint8_t* p = &rgb[(size_t(y) * width + 2 * k + x) * 3];
        p[0] = uint8_t(colours[k].r), p[1] = uint8_t(colours[k].g), p[2] = uint8_t(colours[k].b);
      }
  return rgb;
}

std::vector<Rgb> colour_lattice(int step) {
  std::vector<Rgb> colours;
  for (int r = 0; r < 256; r += step)
    for (int g = 0; g < 256; g += step)
      for (int b = 0; b < 256; b += step) colours.push_back({r, g, b});
  for (const Rgb& c : std::vector<Rgb>{{255, 255, 255}, {255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 0}})
    colours.push_back(c);
  return colours;
}

TEST(PixelConvert, Bt601DefiningPointsAreExact) {
  // White is Y=235 and black Y=16, with neutral chroma 128: the definition of studio range.
  int w, h;
  const auto rgb = uniform_blocks({{255, 255, 255}, {0, 0, 0}}, w, h);
  const Frame yuyv = from_rgb24(rgb.data(), w, h, PixelFormat::YUYV);
  EXPECT_EQ(std::vector<uint8_t>(yuyv.data.begin(), yuyv.data.begin() + 8),
            (std::vector<uint8_t>{235, 128, 235, 128, 16, 128, 16, 128}));
  std::vector<uint8_t> back;
  to_rgb24(yuyv, back);
  EXPECT_EQ(back, rgb);  // and they decode to exactly white and black
}

TEST(PixelConvert, KnownColoursEncodeAsBt601) {
  // Greys, primaries and secondaries against the floating-point equations. The fixed-point
  // coefficients (66/256 for 65.481/255, ...) differ in the third digit, so values may be off by 1.
  const std::vector<Rgb> colours{{128, 128, 128}, {64, 64, 64}, {255, 0, 0}, {0, 255, 0}, {0, 0, 255},
                                 {255, 255, 0},   {0, 255, 255}, {255, 0, 255}, {200, 120, 40}};
  int w, h;
  const auto rgb = uniform_blocks(colours, w, h);
  const Frame yuyv = from_rgb24(rgb.data(), w, h, PixelFormat::YUYV);
  const Frame nv12 = from_rgb24(rgb.data(), w, h, PixelFormat::NV12);
  std::vector<uint8_t> i420;
  rgb24_to_i420(rgb.data(), w, w, h, i420);
  for (size_t k = 0; k < colours.size(); ++k) {
    SCOPED_TRACE(testing::Message() << colours[k].r << "," << colours[k].g << "," << colours[k].b);
    const Yuv e = bt601_encode(colours[k].r, colours[k].g, colours[k].b);
    // YUYV: Y0 U Y1 V per pair of pixels.
    const uint8_t* pair = &yuyv.data[4 * k];
    EXPECT_NEAR(pair[0], e.y, 1.0);
    EXPECT_NEAR(pair[2], e.y, 1.0);
    EXPECT_NEAR(pair[1], e.u, 1.0);
    EXPECT_NEAR(pair[3], e.v, 1.0);
    // NV12: Y plane, then interleaved U V at half resolution.
    EXPECT_NEAR(nv12.data[2 * k], e.y, 1.0);
    const uint8_t* uv = &nv12.data[nv12.bytes_per_line * size_t(h) + 2 * k];
    EXPECT_NEAR(uv[0], e.u, 1.0);
    EXPECT_NEAR(uv[1], e.v, 1.0);
    // I420: Y plane, U plane, V plane.
    const size_t ysize = size_t(w) * h;
    EXPECT_NEAR(i420[2 * k], e.y, 1.0);
    EXPECT_NEAR(i420[ysize + k], e.u, 1.0);
    EXPECT_NEAR(i420[ysize + ysize / 4 + k], e.v, 1.0);
  }
  // A grey has exactly neutral chroma.
  EXPECT_EQ(yuyv.data[1], 128);
  EXPECT_EQ(yuyv.data[3], 128);
}

TEST(PixelConvert, DecodesLikeTheBt601Inverse) {
  // Every (Y, U, V), one per 2-pixel YUYV pair, and the same through NV12. The fixed-point decode
  // rounds the coefficients to 1/256, which moves results by at most 1 level against the exact inverse.
  for (int y = 0; y < 256; ++y) {
    Frame yuyv = Frame::allocate(PixelFormat::YUYV, 2 * 256 * 256, 1);
    Frame nv12 = Frame::allocate(PixelFormat::NV12, 2 * 256 * 256, 2);
    uint8_t* uv = nv12.data.data() + nv12.bytes_per_line * 2;
    for (int u = 0; u < 256; ++u)
      for (int v = 0; v < 256; ++v) {
        const size_t k = size_t(u) * 256 + size_t(v);
        yuyv.data[4 * k] = yuyv.data[4 * k + 2] = uint8_t(y);
        yuyv.data[4 * k + 1] = uint8_t(u);
        yuyv.data[4 * k + 3] = uint8_t(v);
        nv12.data[2 * k] = nv12.data[2 * k + 1] = uint8_t(y);
        nv12.data[nv12.bytes_per_line + 2 * k] = nv12.data[nv12.bytes_per_line + 2 * k + 1] = uint8_t(y);
        uv[2 * k] = uint8_t(u);
        uv[2 * k + 1] = uint8_t(v);
      }
    for (const Frame* f : {&yuyv, &nv12}) {
      std::vector<uint8_t> rgb;
      to_rgb24(*f, rgb);
      int failures = 0;
      for (int u = 0; u < 256 && failures < 5; ++u)
        for (int v = 0; v < 256 && failures < 5; ++v) {
          const Rgb e = bt601_decode(y, u, v);
          const size_t k = size_t(u) * 256 + size_t(v);
          for (int pixel = 0; pixel < 2; ++pixel) {
            const uint8_t* p = &rgb[(2 * k + pixel) * 3];
            const bool near = std::abs(p[0] - e.r) <= 1 && std::abs(p[1] - e.g) <= 1 && std::abs(p[2] - e.b) <= 1;
            if (!near) ++failures;
            EXPECT_TRUE(near) << pixel_format_name(f->format) << " " << y << " " << u << " " << v << ": " << int(p[0])
                              << " " << int(p[1]) << " " << int(p[2]) << " against " << e.r << " " << e.g << " " << e.b;
          }
        }
      ASSERT_EQ(failures, 0);
    }
  }
}

TEST(PixelConvert, YuvRoundTripsOfUniformBlocksStayWithinThreeLevels) {
  // RGB -> 8-bit Y'CbCr -> RGB: Y quantises in steps of 255/219 (+-0.58 levels) and Cb/Cr in steps
  // of 255/224, amplified by up to 1.772 on the way back (+-1.01); with the rounding of each
  // fixed-point stage (+-0.5 twice) the bound is 3 levels per channel.
  int w, h;
  const auto rgb = uniform_blocks(colour_lattice(15), w, h);
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12}) {
    const Frame f = from_rgb24(rgb.data(), w, h, format);
    std::vector<uint8_t> back;
    to_rgb24(f, back);
    ASSERT_EQ(back.size(), rgb.size());
    int worst = 0;
    for (size_t i = 0; i < rgb.size(); ++i) worst = std::max(worst, std::abs(int(back[i]) - int(rgb[i])));
    EXPECT_LE(worst, 3) << pixel_format_name(format);
  }
}

TEST(PixelConvert, SmoothGradientRoundTrips) {
  // A gradient changing by at most 2 levels per pixel: chroma averaged over 2 or 4 pixels is then
  // off by at most 1 level for any one of them, adding at most 1.772 levels to the 3 above.
  const int w = 128, h = 64;
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &rgb[(size_t(y) * w + x) * 3];
      p[0] = uint8_t(2 * x), p[1] = uint8_t(255 - 2 * y), p[2] = uint8_t(x + y);
    }
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12}) {
    std::vector<uint8_t> back;
    to_rgb24(from_rgb24(rgb.data(), w, h, format), back);
    int worst = 0;
    for (size_t i = 0; i < rgb.size(); ++i) worst = std::max(worst, std::abs(int(back[i]) - int(rgb[i])));
    EXPECT_LE(worst, 5) << pixel_format_name(format);
  }
}

TEST(PixelConvert, GreyIsFullRangeLuma) {
  // Every grey level survives RGB -> GREY -> RGB exactly (full range: 0 black, 255 white).
  std::vector<uint8_t> rgb(256 * 3);
  for (int v = 0; v < 256; ++v) rgb[3 * v] = rgb[3 * v + 1] = rgb[3 * v + 2] = uint8_t(v);
  const Frame grey = from_rgb24(rgb.data(), 256, 1, PixelFormat::GREY);
  for (int v = 0; v < 256; ++v) EXPECT_EQ(grey.data[v], v);
  std::vector<uint8_t> back;
  to_rgb24(grey, back);
  EXPECT_EQ(back, rgb);

  // Colours become Y' = 0.299 R + 0.587 G + 0.114 B; the 8-bit weights round to within 1 level.
  int w, h;
  const auto colours = colour_lattice(17);
  const auto blocks = uniform_blocks(colours, w, h);
  const Frame g = from_rgb24(blocks.data(), w, h, PixelFormat::GREY);
  std::vector<uint8_t> luma;
  to_grey(Frame{{}, PixelFormat::RGB24, w, h, size_t(w) * 3, blocks}, luma);
  for (size_t k = 0; k < colours.size(); ++k) {
    const double expected = 0.299 * colours[k].r + 0.587 * colours[k].g + 0.114 * colours[k].b;
    EXPECT_NEAR(g.data[2 * k], expected, 1.0);
    EXPECT_EQ(luma[2 * k], g.data[2 * k]);  // to_grey of RGB24 is the same luma as a GREY frame
  }
}

TEST(PixelConvert, ToGreyTakesTheLumaPlaneOfYuvFrames) {
  int w, h;
  const auto rgb = uniform_blocks(colour_lattice(51), w, h);
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12}) {
    const Frame f = from_rgb24(rgb.data(), w, h, format);
    std::vector<uint8_t> grey;
    to_grey(f, grey);
    ASSERT_EQ(grey.size(), size_t(w) * h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const uint8_t* p = &rgb[(size_t(y) * w + x) * 3];
        // Studio-range Y' (16..235) as the camera delivered it.
        EXPECT_NEAR(grey[size_t(y) * w + x], bt601_encode(p[0], p[1], p[2]).y, 1.0) << pixel_format_name(format);
      }
  }
}

// The tracker's search window converts only its rectangle: those bytes are the whole frame's
// conversion, the others keep what they held, and a rectangle reaching out of the frame is clipped.
TEST(PixelConvert, ToGreyOfARectangleWritesThatRectangleOnly) {
  const int w = 12, h = 6;
  std::vector<uint8_t> rgb(size_t(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t(i * 37 % 251);
  for (const PixelFormat format : {PixelFormat::YUYV, PixelFormat::NV12, PixelFormat::RGB24, PixelFormat::GREY}) {
    const Frame f = from_rgb24(rgb.data(), w, h, format);
    std::vector<uint8_t> whole;
    to_grey(f, whole);
    const PixelRect rect{3, 2, 20, 3};  // columns 3..11 once clipped, rows 2..4
    std::vector<uint8_t> part(size_t(w) * h, uint8_t{7});
    to_grey(f, rect, part);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * w + x;
        const bool inside = x >= 3 && y >= 2 && y < 5;
        EXPECT_EQ(part[i], inside ? whole[i] : uint8_t{7}) << pixel_format_name(format) << " " << x << "," << y;
      }
  }
}

TEST(PixelConvert, Nv12ChromaBelongsToItsOwnTwoByTwoBlock) {
  // Four blocks of different colours in a 4x4 image: each must decode with its own chroma.
  const Rgb colours[2][2] = {{{255, 0, 0}, {0, 255, 0}}, {{0, 0, 255}, {255, 255, 0}}};
  std::vector<uint8_t> rgb(4 * 4 * 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const Rgb& c = colours[y / 2][x / 2];
      uint8_t* p = &rgb[(size_t(y) * 4 + x) * 3];
      p[0] = uint8_t(c.r), p[1] = uint8_t(c.g), p[2] = uint8_t(c.b);
    }
  std::vector<uint8_t> back;
  to_rgb24(from_rgb24(rgb.data(), 4, 4, PixelFormat::NV12), back);
  for (size_t i = 0; i < rgb.size(); ++i) EXPECT_NEAR(back[i], rgb[i], 3.0) << i;
}

TEST(PixelConvert, HonoursPaddedStrides) {
  // The same image with 16 bytes of padding after every row (as V4L2 drivers often deliver) must
  // convert exactly like the tightly packed one.
  int w, h;
  auto colours = colour_lattice(85);
  colours.resize(8);
  auto rgb = uniform_blocks(colours, w, h);
  // Make the image 4 rows high so NV12 has two chroma rows.
  rgb.insert(rgb.end(), rgb.begin(), rgb.end());
  h = 4;
  for (const PixelFormat format : {PixelFormat::GREY, PixelFormat::RGB24, PixelFormat::YUYV, PixelFormat::NV12}) {
    const Frame tight = from_rgb24(rgb.data(), w, h, format);
    Frame padded = tight;
    padded.bytes_per_line = tight.bytes_per_line + 16;
    padded.data.assign(image_bytes(format, w, h, padded.bytes_per_line), 0xAB);
    const int plane_rows = format == PixelFormat::NV12 ? h + h / 2 : h;
    for (int row = 0; row < plane_rows; ++row)
      std::memcpy(&padded.data[size_t(row) * padded.bytes_per_line], &tight.data[size_t(row) * tight.bytes_per_line],
                  tight.bytes_per_line);
    std::vector<uint8_t> a, b;
    to_rgb24(tight, a);
    to_rgb24(padded, b);
    EXPECT_EQ(a, b) << pixel_format_name(format);
    to_grey(tight, a);
    to_grey(padded, b);
    EXPECT_EQ(a, b) << pixel_format_name(format);
  }
}

TEST(PixelConvert, I420TakesTheTopLeftOfAWiderImage) {
  // rgb_width > width: only the top-left width x height pixels are converted.
  int w, h;
  const auto rgb = uniform_blocks({{255, 255, 255}, {0, 0, 0}, {255, 0, 0}}, w, h);
  std::vector<uint8_t> i420;
  rgb24_to_i420(rgb.data(), w, 4, 2, i420);
  ASSERT_EQ(i420.size(), 4u * 2 + 2 * 2);
  EXPECT_EQ(std::vector<uint8_t>(i420.begin(), i420.begin() + 8), (std::vector<uint8_t>{235, 235, 16, 16, 235, 235, 16, 16}));
  EXPECT_EQ(std::vector<uint8_t>(i420.begin() + 8, i420.end()), (std::vector<uint8_t>{128, 128, 128, 128}));
}

}  // namespace
}  // namespace arpipe
