// Recordings of raw Bayer frames: a round trip keeps the packed bytes, and a recording.json that
// claims a Bayer format with a size or stride the packing cannot hold is refused with the file
// and the problem named, as for the other formats.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <tuple>
#include <vector>

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

// A frame's development values (core/raw_colour.h) are read as hostile as the rest: the wrong
// count, a gain that is not positive, a negative black level or a white level past 16 bits are
// refused naming the file, the line and the field. Whether they fit the frame's bit depth is the
// source's check (capture/raw_colour_source.h), made per frame.
TEST(RecordingBayer, BadDevelopmentValuesAreRefusedByName) {
  const fs::path dir = scratch_dir("bayer-raw-values");
  write_recording(dir, PixelFormat::SRGGB10P, kWidth, kHeight, 2);
  const fs::path lines = dir / "frames.jsonl";
  const std::string original = read_file(lines);
  ASSERT_NE(original.find("\"colour_gains\""), std::string::npos) << "frame 0 carries its development values";
  auto error_with = [&](const std::string& field, const std::string& value) {
    // The first frame's value of `field` replaced: an array up to its ']', a number up to ',' or '}'.
    const size_t at = original.find("\"" + field + "\":");
    EXPECT_NE(at, std::string::npos) << field;
    const size_t value_at = at + field.size() + 3;
    const size_t value_end = original[value_at] == '[' ? original.find(']', value_at) + 1
                                                       : original.find_first_of(",}", value_at);
    std::string text = original;
    text.replace(value_at, value_end - value_at, value);
    write_file(lines, text);
    return error_message([&] { RecordingReader reader(dir); });
  };
  for (const auto& [field, value, says] :
       std::vector<std::tuple<std::string, std::string, std::string>>{{"colour_gains", "[1,0,1]", "colour_gains[1]"},
                                                                      {"colour_gains", "[1,1]", "colour_gains"},
                                                                      {"black_level", "[64,64,-1,64]", "black_level[2]"},
                                                                      {"colour_matrix", "[1,0,0,0,1,0,0,0]", "colour_matrix"},
                                                                      {"white_level", "70000", "white_level"}}) {
    const std::string message = error_with(field, value);
    EXPECT_EQ(message.rfind(lines.string(), 0), 0u) << message;
    EXPECT_NE(message.find(says), std::string::npos) << field << " = " << value << ": " << message;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arpipe
