// Corrupt Radiance .hdr input: every truncation of valid files, bad magic, bad resolution lines,
// unsupported formats, bad EXPOSURE, run-length overruns. Each must throw AssetError whose message
// names the file, the place and what was expected; nothing may crash.
#include <gtest/gtest.h>

#include "core/image/radiance_hdr.h"
#include "tests/environment/hdr_test_files.h"

namespace arpipe {
namespace {

using hdr_test::append;
using hdr_test::asset_error_message;
using hdr_test::bytes_of;

std::string decode_error(const std::vector<uint8_t>& bytes, const std::string& name = "probe.hdr") {
  return asset_error_message([&] { decode_radiance_hdr(bytes, name); });
}

void expect_contains(const std::string& message, const std::string& part) {
  EXPECT_NE(message.find(part), std::string::npos) << "message: " << message << "\nexpected to contain: " << part;
}

// Valid files: run-length (width 8, runs and literals), flat (width 3) and old run-length.
std::vector<std::vector<uint8_t>> valid_files() {
  std::vector<uint8_t> rle = bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=2\n\n-Y 2 +X 8\n");
  for (int row = 0; row < 2; ++row) {
    append(rle, {2, 2, 0, 8});
    append(rle, {136, 100, 8, 1, 2, 3, 4, 5, 6, 7, 8, 131, 50, 5, 60, 61, 62, 63, 64, 136, 130});
  }
  std::vector<uint8_t> flat = bytes_of("#?RGBE\n\n-Y 2 +X 3\n");
  for (int i = 0; i < 6; ++i) append(flat, {128, 64, 32, 129 + i});
  std::vector<uint8_t> old = bytes_of("#?RADIANCE\n\n+Y 1 +X 12\n");
  append(old, {128, 64, 32, 129, 1, 1, 1, 10, 20, 20, 20, 130});
  return {rle, flat, old};
}

TEST(RadianceErrors, ValidFilesDecode) {
  for (const auto& bytes : valid_files()) EXPECT_NO_THROW(decode_radiance_hdr(bytes, "valid.hdr"));
}

TEST(RadianceErrors, EveryTruncationThrows) {
  for (const auto& bytes : valid_files())
    for (size_t length = 0; length < bytes.size(); ++length) {
      const std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length));
      const std::string message = decode_error(prefix, "cut.hdr");
      ASSERT_EQ(message.rfind("cut.hdr: ", 0), 0u) << "length " << length << ": " << message;
    }
}

TEST(RadianceErrors, TruncatedHeaderAndPixelsSayWhere) {
  const auto files = valid_files();
  // Cut inside the header's third line ("EXPOSURE=2" is line 3): "the file ends before ...".
  const std::vector<uint8_t> header_cut(files[0].begin(), files[0].begin() + 40);
  expect_contains(decode_error(header_cut), "probe.hdr: header line 3 (byte 34): the file ends before the blank line");
  // Flat file cut one byte short: the last pixel of scanline 2.
  const std::vector<uint8_t> pixel_cut(files[1].begin(), files[1].end() - 1);
  expect_contains(decode_error(pixel_cut), "probe.hdr: scanline 2 of 2 (byte 38): the file ends inside pixel 3 of 3");
}

TEST(RadianceErrors, BadMagic) {
  expect_contains(decode_error(bytes_of("P6\n3 2\n255\n")), "probe.hdr: byte 0: not a Radiance file");
  expect_contains(decode_error(bytes_of("#?JPEG\n\n-Y 1 +X 1\n")), "header line 1: expected \"#?RADIANCE\" or \"#?RGBE\"");
  expect_contains(decode_error({}), "not a Radiance file");
}

TEST(RadianceErrors, BadResolutionLines) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"-Y 0 +X 4", "Y (height) size 0 is outside 1..32768"},
      {"-Y 4 +X 0", "X (width) size 0 is outside 1..32768"},
      {"-Y 2 +X 32769", "X (width) size 32769 is outside 1..32768"},
      {"-Y 20000 +X 20000", "20000 x 20000 pixels is more than the 2^28 allowed"},
      {"-Y 2 +X 9999999", "expected a size for X (width)"},
      {"-Y 2 -Y 3", "expected \"-Y height +X width\""},
      {"Y 2 X 3", "expected \"-Y height +X width\""},
      {"-Y 2 +X", "expected \"-Y height +X width\""},
      {"-Y 2 +X 3 7", "expected \"-Y height +X width\""},
      {"-Y -2 +X 3", "expected a size for Y (height), found \"-2\""},
      {"-Y 2.5 +X 3", "expected a size for Y (height)"},
  };
  for (const auto& [line, expected] : cases) {
    const std::string message = decode_error(bytes_of("#?RADIANCE\n\n" + line + "\n"));
    expect_contains(message, "probe.hdr: resolution line (header line 3): ");
    expect_contains(message, expected);
  }
}

TEST(RadianceErrors, FormatsAndExposure) {
  expect_contains(decode_error(bytes_of("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n")),
                  "probe.hdr: header line 2: FORMAT=32-bit_rle_xyze (CIE XYZ pixels) is not supported");
  expect_contains(decode_error(bytes_of("#?RADIANCE\nFORMAT=16-bit\n\n-Y 1 +X 1\n")),
                  "header line 2: unknown FORMAT=\"16-bit\", expected FORMAT=32-bit_rle_rgbe");
  for (const std::string value : {"abc", "0", "-1", "1e999", "", "2x"})
    expect_contains(decode_error(bytes_of("#?RADIANCE\n# c\nEXPOSURE=" + value + "\n\n-Y 1 +X 1\n")),
                    "header line 3: EXPOSURE=\"" + value + "\" is not a positive number");
  // A tiny EXPOSURE makes the brightest RGBE value overflow a float: said, with the pixel.
  std::vector<uint8_t> bytes = bytes_of("#?RADIANCE\nEXPOSURE=1e-10\n\n-Y 1 +X 2\n");
  append(bytes, {0, 0, 0, 0, 255, 255, 255, 255});
  expect_contains(decode_error(bytes), "probe.hdr: pixel (1, 0): RGBE (255, 255, 255, 255) divided by EXPOSURE");
}

TEST(RadianceErrors, RunLengthOverrunsAndMismatches) {
  const std::string head = "#?RADIANCE\n\n-Y 2 +X 8\n";  // 22 bytes
  // Scanline 2's red channel: a run of 6 after a literal of 3 overruns the 8 pixels. Scanline 1
  // is 4 + 4 * 2 = 12 bytes (runs of 8), scanline 2's header 4 more: the bad count is at byte
  // 22 + 12 + 4 + 4 = 42.
  std::vector<uint8_t> bytes = bytes_of(head);
  append(bytes, {2, 2, 0, 8, 136, 1, 136, 1, 136, 1, 136, 136});
  append(bytes, {2, 2, 0, 8, 3, 1, 2, 3, 134, 9});
  expect_contains(decode_error(bytes), "probe.hdr: scanline 2 of 2 (byte 42): run-length data overruns the 8-pixel width");
  // A literal that overruns.
  bytes = bytes_of(head);
  append(bytes, {2, 2, 0, 8, 9, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  expect_contains(decode_error(bytes), "scanline 1 of 2 (byte 26): run-length data overruns the 8-pixel width");
  // The scanline header's width differs from the image's.
  bytes = bytes_of(head);
  append(bytes, {2, 2, 0, 9});
  expect_contains(decode_error(bytes), "scanline 1 of 2 (byte 22): run-length scanline declares 9 pixels, expected the image's 8");
  // Old-style repeats: before any pixel, and past the end of the scanline.
  bytes = bytes_of("#?RADIANCE\n\n-Y 1 +X 4\n");
  append(bytes, {1, 1, 1, 3});
  expect_contains(decode_error(bytes), "scanline 1 of 1 (byte 22): an old-style run-length repeat comes before any pixel");
  bytes = bytes_of("#?RADIANCE\n\n-Y 1 +X 4\n");
  append(bytes, {9, 9, 9, 130, 1, 1, 1, 4});
  expect_contains(decode_error(bytes), "(byte 26): old-style run-length repeat of 4 overruns the 4-pixel width at pixel 1");
}

TEST(RadianceErrors, HugeDeclaredSizeWithFewBytesFailsCheaply) {
  // 16384 x 16384 declared (2^28 pixels, allowed) but only a few bytes present: the decoder only
  // holds the scanline it reads, so this fails on truncation without a gigabyte allocation.
  std::vector<uint8_t> bytes = bytes_of("#?RADIANCE\n\n-Y 16384 +X 16384\n");
  append(bytes, {2, 2, 0x40, 0x00, 200, 1});
  expect_contains(decode_error(bytes), "scanline 1 of 16384");
}

TEST(RadianceErrors, MissingFileNamesIt) {
  const std::string message = asset_error_message([] { read_radiance_hdr("/nonexistent/dir/probe.hdr"); });
  expect_contains(message, "/nonexistent/dir/probe.hdr: cannot open");
}

}  // namespace
}  // namespace arpipe
