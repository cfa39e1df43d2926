// Writing and reading back Radiance .hdr files, run-length and flat: every channel comes back
// within RGBE's quantisation step, and a failed write leaves an existing file untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

// Random light-probe-like content: log-uniform over 1e-4..1e5, some black pixels and horizontal
// runs of one colour (so the run-length writer has runs to find as well as literals).
HdrImage random_image(int width, int height, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> log_value(std::log(1e-4), std::log(1e5));
  std::uniform_int_distribution<int> kind(0, 9);
  HdrImage image{width, height, std::vector<float>(3 * static_cast<size_t>(width) * height)};
  for (int y = 0; y < height; ++y) {
    float r = 0, g = 0, b = 0;
    for (int x = 0; x < width; ++x) {
      const int k = kind(rng);
      if (x == 0 || k < 5) {  // new colour; else repeat the previous one (a run)
        r = static_cast<float>(std::exp(log_value(rng)));
        g = static_cast<float>(std::exp(log_value(rng)));
        b = static_cast<float>(std::exp(log_value(rng)));
        if (k == 0) r = g = b = 0;
      }
      float* p = &image.rgb[3 * (static_cast<size_t>(y) * width + x)];
      p[0] = r, p[1] = g, p[2] = b;
    }
  }
  return image;
}

// Ward's encoding keeps floor(c 2^(8 - e)) where the largest channel v = f 2^e, f in [0.5, 1), and
// Walter's decode returns byte 2^(e - 8): so 0 <= c - decoded < 2^(e - 8) <= 2 v 2^-8 = 2^-7 v.
// (The step is 2^-8 of 2^e, i.e. up to 2^-7 of the largest channel when v is just above a power
// of two; Ward's own decode, (byte + 0.5) 2^(e - 8), would halve that.) Below 1e-32 it is black.
void expect_within_rgbe_step(const HdrImage& original, const HdrImage& decoded) {
  ASSERT_EQ(decoded.width, original.width);
  ASSERT_EQ(decoded.height, original.height);
  double worst_relative = 0;
  for (int y = 0; y < original.height; ++y)
    for (int x = 0; x < original.width; ++x) {
      const Vec3 c = original.at(x, y), d = decoded.at(x, y);
      const double v = std::max({c[0], c[1], c[2]});
      if (v < 1e-32) {
        EXPECT_EQ(d, (Vec3{0, 0, 0}));
        continue;
      }
      int e = 0;
      std::frexp(v, &e);
      const double step = std::ldexp(1.0, e - 8);
      for (int k = 0; k < 3; ++k) {
        ASSERT_GE(c[k] - d[k], 0) << x << "," << y;
        ASSERT_LT(c[k] - d[k], step) << x << "," << y;
        worst_relative = std::max(worst_relative, (c[k] - d[k]) / v);
      }
    }
  EXPECT_LE(worst_relative, std::ldexp(1.0, -7));
}

TEST(RadianceRoundTrip, RunLengthAndFlatWithinTheQuantisationStep) {
  const auto dir = hdr_test::scratch_dir();
  const HdrImage image = random_image(300, 17, 7);
  write_radiance_hdr(dir / "rle.hdr", image, true);
  write_radiance_hdr(dir / "flat.hdr", image, false);
  const std::vector<uint8_t> rle = hdr_test::read_bytes(dir / "rle.hdr"), flat = hdr_test::read_bytes(dir / "flat.hdr");
  // The flat file is exactly header + 4 bytes per pixel; the run-length one is smaller (half the
  // pixels repeat their neighbour).
  const std::string header = "#?RADIANCE\nSOFTWARE=arpipe\nFORMAT=32-bit_rle_rgbe\n\n-Y 17 +X 300\n";
  EXPECT_EQ(flat.size(), header.size() + 4u * 300 * 17);
  EXPECT_LT(rle.size(), flat.size() * 9 / 10);
  // New-style scanlines start 02 02 hi lo (300 = 0x012c).
  ASSERT_GT(rle.size(), header.size() + 4);
  EXPECT_EQ(rle[header.size()], 2);
  EXPECT_EQ(rle[header.size() + 1], 2);
  EXPECT_EQ(rle[header.size() + 2], 0x01);
  EXPECT_EQ(rle[header.size() + 3], 0x2c);
  expect_within_rgbe_step(image, read_radiance_hdr(dir / "rle.hdr"));
  expect_within_rgbe_step(image, read_radiance_hdr(dir / "flat.hdr"));
  // Both encodings hold the same quantised pixels.
  EXPECT_EQ(read_radiance_hdr(dir / "rle.hdr").rgb, read_radiance_hdr(dir / "flat.hdr").rgb);
}

TEST(RadianceRoundTrip, NarrowImagesAreWrittenFlat) {
  // New-style run length needs 8 <= width <= 32767; narrower images go flat even when asked.
  const auto dir = hdr_test::scratch_dir();
  const HdrImage image = random_image(5, 4, 11);
  write_radiance_hdr(dir / "narrow.hdr", image, true);
  expect_within_rgbe_step(image, read_radiance_hdr(dir / "narrow.hdr"));
}

TEST(RadianceRoundTrip, KnownEncodings) {
  // 1.0 = 0.5 * 2^1: e = 1, byte floor(1 * 2^7) = 128, exponent 129 (as Radiance writes white).
  // 0.75 = 0.75 * 2^0: e = 0, bytes floor(0.75 * 256) = 192, floor(0.1 * 256) = 25, 0; exponent 128.
  const auto dir = hdr_test::scratch_dir();
  const HdrImage image{2, 1, {1, 1, 1, 0.75f, 0.1f, 0}};
  write_radiance_hdr(dir / "known.hdr", image, false);
  const std::vector<uint8_t> bytes = hdr_test::read_bytes(dir / "known.hdr");
  ASSERT_GE(bytes.size(), 8u);
  const std::vector<uint8_t> pixels(bytes.end() - 8, bytes.end());
  EXPECT_EQ(pixels, (std::vector<uint8_t>{128, 128, 128, 129, 192, 25, 0, 128}));
}

TEST(RadianceRoundTrip, FailedWriteKeepsTheExistingFile) {
  const auto dir = hdr_test::scratch_dir();
  const HdrImage good = random_image(9, 3, 3);
  write_radiance_hdr(dir / "probe.hdr", good, true);
  const std::vector<uint8_t> before = hdr_test::read_bytes(dir / "probe.hdr");

  HdrImage bad = good;
  bad.rgb[3 * (9 + 4) + 1] = -1;  // pixel (4, 1), green
  const std::string message = hdr_test::asset_error_message([&] { write_radiance_hdr(dir / "probe.hdr", bad); });
  EXPECT_NE(message.find("probe.hdr"), std::string::npos) << message;
  EXPECT_NE(message.find("pixel (4, 1)"), std::string::npos) << message;
  EXPECT_EQ(hdr_test::read_bytes(dir / "probe.hdr"), before);

  // A directory that does not exist: AssetError, nothing created.
  hdr_test::asset_error_message([&] { write_radiance_hdr(dir / "missing" / "probe.hdr", good); });
  EXPECT_FALSE(std::filesystem::exists(dir / "missing"));
  // No temporary left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
}

}  // namespace
}  // namespace arpipe
