// OpenEXR light probes: half-float round trip, data-window offsets, luminance-only files, bad
// texels (NaN, infinity, negative) named by pixel, truncation at every length, and the magic-byte
// dispatch of read_hdr_image. Files with special content are written with the library directly,
// through its C interface (the C++ headers need Imath's include path, which this target lacks).
#include <gtest/gtest.h>

#include <OpenEXR/ImfCRgbaFile.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/image/hdr_file.h"
#include "core/image/openexr_file.h"
#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

using hdr_test::asset_error_message;

void expect_contains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "message: " << message << "\nexpected to contain: " << part;
}

struct Window {
  int x0, y0, width, height;
};

ImfHalf half_bits(double value) {
  ImfHalf h = 0;
  ImfFloatToHalf(static_cast<float>(value), &h);
  return h;
}

// A half RGB (or luminance, channels = IMF_WRITE_Y) file with the given data window; `bits(x, y)`
// gives the raw halves of pixel (x, y) of the window, so NaN and infinity can be written too.
void write_half_exr(const std::filesystem::path& file, Window window,
                    const std::function<std::array<ImfHalf, 3>(int, int)>& bits, int channels = IMF_WRITE_RGB) {
  std::vector<ImfRgba> pixels(static_cast<size_t>(window.width) * window.height);
  for (int y = 0; y < window.height; ++y)
    for (int x = 0; x < window.width; ++x) {
      const std::array<ImfHalf, 3> rgb = bits(x, y);
      pixels[static_cast<size_t>(y) * window.width + x] = ImfRgba{rgb[0], rgb[1], rgb[2], half_bits(1)};
    }
  ImfHeader* header = ImfNewHeader();
  ImfHeaderSetDisplayWindow(header, 0, 0, 63, 63);
  ImfHeaderSetDataWindow(header, window.x0, window.y0, window.x0 + window.width - 1, window.y0 + window.height - 1);
  ImfOutputFile* out = ImfOpenOutputFile(file.c_str(), header, channels);
  ImfDeleteHeader(header);
  ASSERT_NE(out, nullptr) << ImfErrorMessage();
  // The library addresses pixel (x, y) at base + x + y * width.
  const auto base = reinterpret_cast<uintptr_t>(pixels.data()) -
                    static_cast<uintptr_t>(static_cast<intptr_t>(window.x0) + static_cast<intptr_t>(window.y0) * window.width) *
                        sizeof(ImfRgba);
  ASSERT_TRUE(ImfOutputSetFrameBuffer(out, reinterpret_cast<const ImfRgba*>(base), 1, static_cast<size_t>(window.width)));
  ASSERT_TRUE(ImfOutputWritePixels(out, window.height)) << ImfErrorMessage();
  ASSERT_TRUE(ImfCloseOutputFile(out));
}

std::function<std::array<ImfHalf, 3>(int, int)> from_values(const std::function<Vec3(int, int)>& value) {
  return [value](int x, int y) {
    const Vec3 v = value(x, y);
    return std::array<ImfHalf, 3>{half_bits(v[0]), half_bits(v[1]), half_bits(v[2])};
  };
}

TEST(OpenExrFile, HalfRoundTripWithinHalfPrecision) {
  const auto dir = hdr_test::scratch_dir();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> log_value(std::log(1e-3), std::log(6e4));
  HdrImage image{31, 9, std::vector<float>(3 * 31 * 9)};
  for (float& v : image.rgb) v = static_cast<float>(std::exp(log_value(rng)));
  image.rgb[0] = 0;
  write_openexr(dir / "probe.exr", image);
  const HdrImage back = read_openexr(dir / "probe.exr");
  ASSERT_EQ(back.width, 31);
  ASSERT_EQ(back.height, 9);
  // Half has 10 stored mantissa bits and rounds to nearest: relative error <= 2^-11 for normal
  // values (all of these are >= 1e-3 > 2^-14, half's smallest normal); 0 stays 0.
  for (size_t i = 0; i < image.rgb.size(); ++i)
    ASSERT_LE(std::abs(back.rgb[i] - image.rgb[i]), std::ldexp(1.0, -11) * image.rgb[i]) << i;
  EXPECT_EQ(back.rgb[0], 0);
}

TEST(OpenExrFile, DataWindowOffsetIsHandled) {
  const auto dir = hdr_test::scratch_dir();
  // Window (10, 20) - (13, 22): 4 x 3 pixels; values are exact in float.
  write_half_exr(dir / "window.exr", {10, 20, 4, 3}, from_values([](int x, int y) {
                   return Vec3{double(x), double(y), 100.0 + x + 10 * y};  // exact in half
                 }));
  const HdrImage image = read_hdr_image(dir / "window.exr");
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) EXPECT_EQ(image.at(x, y), (Vec3{double(x), double(y), 100.0 + x + 10 * y}));
  // A negative origin too.
  write_half_exr(dir / "negative.exr", {-5, -7, 3, 1}, from_values([](int x, int) { return Vec3{x + 1.0, 2, 3}; }));
  const HdrImage negative = read_hdr_image(dir / "negative.exr");
  ASSERT_EQ(negative.width, 3);
  ASSERT_EQ(negative.height, 1);
  EXPECT_EQ(negative.at(2, 0), (Vec3{3, 2, 3}));
}

TEST(OpenExrFile, LuminanceOnlyFileBecomesGrey) {
  const auto dir = hdr_test::scratch_dir();
  write_half_exr(dir / "grey.exr", {0, 0, 3, 2}, from_values([](int x, int y) {
                   const double grey = 0.5 * (3 * y + x + 1);
                   return Vec3{grey, grey, grey};
                 }),
                 IMF_WRITE_Y);
  const HdrImage image = read_hdr_image(dir / "grey.exr");
  ASSERT_EQ(image.width, 3);
  // Y = 0.2126 R + 0.7152 G + 0.0722 B of a grey is the grey, and the library gives R = G = B = Y;
  // halves of k/2 are exact, the luminance weights sum to 1 within half rounding (2^-11).
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.at(i % 3, i / 3)[c], 0.5 * (i + 1), 0.5 * (i + 1) * std::ldexp(1.0, -10));
}

TEST(OpenExrFile, BadTexelsAreNamedByPixel) {
  const auto dir = hdr_test::scratch_dir();
  // Half bit patterns: 0x7e00 a quiet NaN, 0x7c00 +infinity, 0xb400 = -0.25.
  const std::vector<std::pair<ImfHalf, std::string>> cases = {
      {0x7e00, "channel G: NaN value"},
      {0x7c00, "channel G: infinite value inf"},
      {0xb400, "channel G: negative value -0.25"},
  };
  for (const auto& [bad, expected] : cases) {
    const ImfHalf one = half_bits(1);
    write_half_exr(dir / "bad.exr", {0, 0, 5, 4}, [&](int x, int y) {
      return x == 3 && y == 2 ? std::array<ImfHalf, 3>{one, bad, one} : std::array<ImfHalf, 3>{one, one, one};
    });
    const std::string message = asset_error_message([&] { read_hdr_image(dir / "bad.exr"); });
    expect_contains(message, (dir / "bad.exr").string() + ": pixel (3, 2) " + expected);
  }
  // The writers refuse them too, and half's range.
  HdrImage image{2, 1, {1, 1, 1, 1, std::numeric_limits<float>::quiet_NaN(), 1}};
  expect_contains(asset_error_message([&] { write_openexr(dir / "out.exr", image); }), "pixel (1, 0) channel G: NaN");
  image.rgb[4] = 70000;
  expect_contains(asset_error_message([&] { write_openexr(dir / "out.exr", image); }),
                  "pixel (1, 0): value 70000 is above half precision's maximum 65504");
  EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
}

TEST(OpenExrFile, EveryTruncationThrows) {
  const auto dir = hdr_test::scratch_dir();
  HdrImage image{5, 4, std::vector<float>(60)};
  for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = 0.1f * static_cast<float>(i);
  write_openexr(dir / "whole.exr", image);
  const std::vector<uint8_t> bytes = hdr_test::read_bytes(dir / "whole.exr");
  for (size_t length = 0; length < bytes.size(); ++length) {
    hdr_test::write_bytes(dir / "cut.exr", std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length)));
    const std::string message = asset_error_message([&] { read_openexr(dir / "cut.exr"); });
    ASSERT_EQ(message.rfind((dir / "cut.exr").string() + ": ", 0), 0u) << "length " << length << ": " << message;
  }
}

// Byte offset just after `text` in `bytes`.
size_t after(const std::vector<uint8_t>& bytes, const std::string& text) {
  const auto it = std::search(bytes.begin(), bytes.end(), text.begin(), text.end());
  EXPECT_NE(it, bytes.end()) << text;
  return static_cast<size_t>(it - bytes.begin()) + text.size();
}

TEST(OpenExrFile, CorruptHeaderIsRejectedBeforeTheLibraryAllocates) {
  // OpenEXR 3.1 allocates what an attribute's size field or the data window says before it finds
  // the file short (gigabytes, seconds under ASan); the reader checks the header first.
  const auto dir = hdr_test::scratch_dir();
  write_openexr(dir / "good.exr", HdrImage{4, 3, std::vector<float>(36, 1.0f)});
  const std::vector<uint8_t> good = hdr_test::read_bytes(dir / "good.exr");
  // dataWindow: name, "box2i", size 16, then xMin yMin xMax yMax (int32, little-endian).
  std::vector<uint8_t> wide = good;
  const size_t window = after(wide, std::string("dataWindow\0box2i\0", 17)) + 4;
  wide[window + 8] = 0xa0, wide[window + 9] = 0x86, wide[window + 10] = 0x01, wide[window + 11] = 0;  // xMax = 100000
  hdr_test::write_bytes(dir / "wide.exr", wide);
  expect_contains(asset_error_message([&] { read_openexr(dir / "wide.exr"); }),
                  "wide.exr: data window (0, 0) - (100000, 2) is 100001 x 3 pixels; expected sides of 1..32768");
  // An attribute whose size field claims 2^30 bytes.
  std::vector<uint8_t> big = good;
  const size_t size_field = after(big, std::string("channels\0chlist\0", 16));
  big[size_field + 3] = 0x40;
  hdr_test::write_bytes(dir / "big.exr", big);
  expect_contains(asset_error_message([&] { read_openexr(dir / "big.exr"); }),
                  "big.exr: OpenEXR header (byte " + std::to_string(size_field + 4) + "): attribute \"channels\" declares");
}

TEST(OpenExrFile, MissingFileAndOtherFormats) {
  const auto dir = hdr_test::scratch_dir();
  expect_contains(asset_error_message([&] { read_openexr(dir / "none.exr"); }), (dir / "none.exr").string() + ": cannot open");
  expect_contains(asset_error_message([&] { read_hdr_image(dir / "none.exr"); }), (dir / "none.exr").string() + ": cannot open");
  hdr_test::write_bytes(dir / "probe.png", {0x89, 'P', 'N', 'G', '\r', '\n'});
  expect_contains(asset_error_message([&] { read_hdr_image(dir / "probe.png"); }),
                  "probe.png: expected a Radiance .hdr or OpenEXR .exr file (magic \"#?\" or 76 2f 31 01), found bytes 89 50 4e 47");
  hdr_test::write_bytes(dir / "empty.hdr", {});
  expect_contains(asset_error_message([&] { read_hdr_image(dir / "empty.hdr"); }), "empty.hdr: expected a Radiance .hdr or OpenEXR");
}

TEST(OpenExrFile, DispatchReadsBothFormats) {
  const auto dir = hdr_test::scratch_dir();
  const HdrImage image{2, 1, {1, 0.5f, 0.25f, 2, 4, 8}};  // exact in both RGBE and half
  write_openexr(dir / "a.exr", image);
  write_radiance_hdr(dir / "a.hdr", image);
  EXPECT_EQ(read_hdr_image(dir / "a.exr").rgb, image.rgb);
  EXPECT_EQ(read_hdr_image(dir / "a.hdr").rgb, image.rgb);
  // The extension does not matter, the magic does.
  std::filesystem::copy_file(dir / "a.exr", dir / "exr-named.hdr");
  EXPECT_EQ(read_hdr_image(dir / "exr-named.hdr").rgb, image.rgb);
}

}  // namespace
}  // namespace arpipe
