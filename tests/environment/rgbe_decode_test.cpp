// Decoding Radiance .hdr bytes written by hand: Walter's RGBE convention, EXPOSURE, the eight
// resolution-line orientations, new-style run-length scanlines with runs and literals, old-style
// run-length repeats and flat scanlines. Expected values are worked out in the comments.
#include <gtest/gtest.h>

#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

using hdr_test::append;
using hdr_test::bytes_of;

std::vector<uint8_t> header(const std::string& resolution, const std::string& extra = "") {
  return bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + extra + "\n" + resolution + "\n");
}

TEST(RgbeDecode, WalterConventionByHand) {
  std::vector<uint8_t> bytes = header("-Y 1 +X 3");
  // (128, 64, 32, 129): factor 2^(129 - 136) = 2^-7 = 1/128, so 128/128 = 1, 64/128 = 0.5, 32/128 = 0.25.
  append(bytes, {128, 64, 32, 129});
  // (200, 10, 10, 0): exponent byte 0 means black whatever the mantissas.
  append(bytes, {200, 10, 10, 0});
  // (255, 1, 0, 140): factor 2^(140 - 136) = 16: 255 * 16 = 4080, 1 * 16 = 16, 0.
  append(bytes, {255, 1, 0, 140});
  const HdrImage image = decode_radiance_hdr(bytes, "hand.hdr");
  ASSERT_EQ(image.width, 3);
  ASSERT_EQ(image.height, 1);
  EXPECT_EQ(image.at(0, 0), (Vec3{1.0, 0.5, 0.25}));  // powers of two: exact
  EXPECT_EQ(image.at(1, 0), (Vec3{0, 0, 0}));
  EXPECT_EQ(image.at(2, 0), (Vec3{4080, 16, 0}));
}

TEST(RgbeDecode, RgbeMagicAndNoFormatLineAreAccepted) {
  std::vector<uint8_t> bytes = bytes_of("#?RGBE\n# a comment\nGAMMA=1.0\n\n-Y 1 +X 1\n");
  append(bytes, {128, 128, 128, 129});  // 1, 1, 1
  EXPECT_EQ(decode_radiance_hdr(bytes, "rgbe.hdr").at(0, 0), (Vec3{1, 1, 1}));
}

TEST(RgbeDecode, ExposureLinesMultiplyAndPixelsAreDividedByTheProduct) {
  // Radiance: EXPOSURE= is a multiplier already applied to the pixels; several lines multiply;
  // divide by the product to get the original values. 2 * 4 = 8: 1.0 / 8 = 0.125.
  std::vector<uint8_t> bytes = header("-Y 1 +X 1", "EXPOSURE=2\nEXPOSURE= 4.0\n");
  append(bytes, {128, 64, 32, 129});
  EXPECT_EQ(decode_radiance_hdr(bytes, "exposure.hdr").at(0, 0), (Vec3{0.125, 0.0625, 0.03125}));
}

// A 3 x 2 image with pixel (x, y) = (10 x + y + 1) / 128 in red (exponent 129 -> byte / 128),
// stored in file order for each orientation of the resolution line.
struct Orientation {
  std::string line;
  std::vector<std::pair<int, int>> file_order;  // (x, y) of each stored pixel in turn
};

TEST(RgbeDecode, AllEightOrientations) {
  const std::vector<Orientation> cases = {
      {"-Y 2 +X 3", {{0, 0}, {1, 0}, {2, 0}, {0, 1}, {1, 1}, {2, 1}}},  // standard: top row first, left to right
      {"-Y 2 -X 3", {{2, 0}, {1, 0}, {0, 0}, {2, 1}, {1, 1}, {0, 1}}},
      {"+Y 2 +X 3", {{0, 1}, {1, 1}, {2, 1}, {0, 0}, {1, 0}, {2, 0}}},  // bottom row first
      {"+Y 2 -X 3", {{2, 1}, {1, 1}, {0, 1}, {2, 0}, {1, 0}, {0, 0}}},
      {"+X 3 -Y 2", {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 0}, {2, 1}}},  // column-major, left column first
      {"+X 3 +Y 2", {{0, 1}, {0, 0}, {1, 1}, {1, 0}, {2, 1}, {2, 0}}},
      {"-X 3 -Y 2", {{2, 0}, {2, 1}, {1, 0}, {1, 1}, {0, 0}, {0, 1}}},
      {"-X 3 +Y 2", {{2, 1}, {2, 0}, {1, 1}, {1, 0}, {0, 1}, {0, 0}}},
  };
  for (const Orientation& c : cases) {
    std::vector<uint8_t> bytes = header(c.line);
    for (const auto& [x, y] : c.file_order) append(bytes, {10 * x + y + 1, 0, 0, 129});
    const HdrImage image = decode_radiance_hdr(bytes, "orientation.hdr");
    ASSERT_EQ(image.width, 3) << c.line;
    ASSERT_EQ(image.height, 2) << c.line;
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) EXPECT_EQ(image.at(x, y)[0], (10 * x + y + 1) / 128.0) << c.line << " at " << x << "," << y;
  }
}

TEST(RgbeDecode, NewStyleRunLengthWithRunsAndLiterals) {
  // Width 8, one scanline: 0x02 0x02 0x00 0x08, then each channel on its own.
  std::vector<uint8_t> bytes = header("-Y 1 +X 8");
  append(bytes, {2, 2, 0, 8});
  append(bytes, {128 + 8, 100});                            // R: a run of 8 x 100
  append(bytes, {8, 1, 2, 3, 4, 5, 6, 7, 8});               // G: a literal of 8 bytes
  append(bytes, {128 + 3, 50, 5, 60, 61, 62, 63, 64});      // B: a run of 3 x 50, then 5 literals
  append(bytes, {128 + 2, 136, 128 + 1, 136, 5, 136, 136, 136, 136, 136});  // E: run 2, run 1, literal 5
  const HdrImage image = decode_radiance_hdr(bytes, "rle.hdr");
  ASSERT_EQ(image.width, 8);
  // Exponent 136: factor 2^0 = 1, so every channel is its byte.
  const int blue[8] = {50, 50, 50, 60, 61, 62, 63, 64};
  for (int x = 0; x < 8; ++x) EXPECT_EQ(image.at(x, 0), (Vec3{100, x + 1.0, double(blue[x])})) << x;
}

TEST(RgbeDecode, LiteralOf128AndRunOf127) {
  // Count 128 is a literal of 128 bytes (runs need count > 128); 128 + 127 = 255 is a run of 127.
  std::vector<uint8_t> bytes = header("-Y 1 +X 255");
  append(bytes, {2, 2, 0, 255});
  for (int channel = 0; channel < 4; ++channel) {
    bytes.push_back(128);
    for (int i = 0; i < 128; ++i) bytes.push_back(channel == 3 ? 136 : static_cast<uint8_t>(i));
    append(bytes, {255, channel == 3 ? 136 : 7});
  }
  const HdrImage image = decode_radiance_hdr(bytes, "long.hdr");
  EXPECT_EQ(image.at(0, 0), (Vec3{0, 0, 0}));
  EXPECT_EQ(image.at(127, 0), (Vec3{127, 127, 127}));
  EXPECT_EQ(image.at(128, 0), (Vec3{7, 7, 7}));
  EXPECT_EQ(image.at(254, 0), (Vec3{7, 7, 7}));
}

TEST(RgbeDecode, OldStyleRunLengthRepeats) {
  // Width 300: pixel A, then (1,1,1,43) repeats A 43 times, then (1,1,1,1) repeats it 1 << 8 = 256
  // more times (consecutive repeats shift by 8): 1 + 43 + 256 = 300 pixels, all A.
  std::vector<uint8_t> bytes = header("-Y 2 +X 300");
  append(bytes, {64, 32, 16, 130, 1, 1, 1, 43, 1, 1, 1, 1});
  // Second row: B, a repeat of 2 (B B B), flat C, then repeats of 40 and 1 << 8: 1 + 2 + 1 + 40 + 256 = 300.
  append(bytes, {10, 20, 30, 136, 1, 1, 1, 2, 40, 50, 60, 136, 1, 1, 1, 40, 1, 1, 1, 1});
  const HdrImage image = decode_radiance_hdr(bytes, "old.hdr");
  // (64, 32, 16, 130): factor 2^-6: 1, 0.5, 0.25.
  for (int x = 0; x < 300; ++x) ASSERT_EQ(image.at(x, 0), (Vec3{1, 0.5, 0.25})) << x;
  for (int x = 0; x < 3; ++x) EXPECT_EQ(image.at(x, 1), (Vec3{10, 20, 30})) << x;
  for (int x = 3; x < 300; ++x) ASSERT_EQ(image.at(x, 1), (Vec3{40, 50, 60})) << x;
}

TEST(RgbeDecode, FlatScanlinesOfAnyWidth) {
  // Widths below 8 cannot use new-style run length: four bytes per pixel.
  std::vector<uint8_t> bytes = header("-Y 2 +X 2");
  append(bytes, {128, 0, 0, 129, 0, 128, 0, 129, 0, 0, 128, 129, 128, 128, 128, 130});
  const HdrImage image = decode_radiance_hdr(bytes, "flat.hdr");
  EXPECT_EQ(image.at(0, 0), (Vec3{1, 0, 0}));
  EXPECT_EQ(image.at(1, 0), (Vec3{0, 1, 0}));
  EXPECT_EQ(image.at(0, 1), (Vec3{0, 0, 1}));
  EXPECT_EQ(image.at(1, 1), (Vec3{2, 2, 2}));
}

}  // namespace
}  // namespace arpipe
