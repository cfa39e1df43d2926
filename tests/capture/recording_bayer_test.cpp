// Recordings of raw Bayer frames: a round trip keeps the packed bytes, and a recording.json that
// claims a Bayer format with a size or stride the packing cannot hold is refused with the file
// and the problem named, as for the other formats.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "capture/recording/recording_reader.h"
#include "capture_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

// 8 x 4 SRGGB10P: 10 bytes a row.
constexpr int kWidth = 8, kHeight = 4;

std::string with(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(RecordingBayer, PackedFramesRoundTrip) {
  const fs::path dir = scratch_dir("bayer-roundtrip");
  write_recording(dir, PixelFormat::SRGGB10P, kWidth, kHeight, 2);
  const RecordingReader reader(dir);
  EXPECT_EQ(reader.info().pixel_format, PixelFormat::SRGGB10P);
  EXPECT_EQ(reader.info().bytes_per_line, 10u);
  Frame frame;
  reader.read(1, frame);
  EXPECT_EQ(frame.format, PixelFormat::SRGGB10P);
  EXPECT_EQ(frame.data.size(), 40u);
}

TEST(RecordingBayer, WrongSizesAndStridesAreRefusedByName) {
  const fs::path dir = scratch_dir("bayer-hostile");
  write_recording(dir, PixelFormat::SRGGB10P, kWidth, kHeight, 2);
  const fs::path json = dir / "recording.json";
  const std::string original = read_file(json);
  auto error_with = [&](const std::string& from, const std::string& to) {
    write_file(json, with(original, from, to));
    return error_message([&] { RecordingReader reader(dir); });
  };
  // A stride below 5 bytes per 4 pixels.
  std::string message = error_with("\"bytes_per_line\": 10", "\"bytes_per_line\": 9");
  EXPECT_EQ(message.rfind(json.string(), 0), 0u) << message;
  EXPECT_NE(message.find("bytes_per_line"), std::string::npos) << message;
  // A width that is not whole 4-pixel groups, and an odd height (half a CFA cell).
  message = error_with(fmt::format("\"width\": {}", kWidth), "\"width\": 6");
  EXPECT_EQ(message.rfind(json.string(), 0), 0u) << message;
  EXPECT_NE(message.find("multiple of 4"), std::string::npos) << message;
  message = error_with(fmt::format("\"height\": {}", kHeight), "\"height\": 3");
  EXPECT_EQ(message.rfind(json.string(), 0), 0u) << message;
  EXPECT_NE(message.find("even width and height"), std::string::npos) << message;
  // A format name that does not exist.
  message = error_with("\"SRGGB10P\"", "\"SRGGB11P\"");
  EXPECT_EQ(message.rfind(json.string(), 0), 0u) << message;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
