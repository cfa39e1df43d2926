// Recording format v1 under damage: a recording cut at any byte opens with a warning and yields its
// complete frames; every other defect is a RecordingError naming the file and the place in it.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture_test_support.h"
#include "core/log.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

constexpr int kWidth = 32, kHeight = 16;  // GREY: 512 bytes per frame
constexpr size_t kFrameBytes = size_t(kWidth) * kHeight;

class DamagedRecording : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = scratch_dir(std::string("damage-") + test->name());
    write_recording(dir_, PixelFormat::GREY, kWidth, kHeight, 3);
  }
  fs::path path(const char* name) const { return dir_ / name; }
  std::string open_error() const {
    return error_message([&] { RecordingReader reader(dir_); });
  }
  // Replaces the first occurrence of `from` in a file.
  void edit(const char* name, const std::string& from, const std::string& to) const {
    std::string text = read_file(path(name));
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from << " not in " << name;
    text.replace(at, from.size(), to);
    write_file(path(name), text);
  }
  static bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  }

  fs::path dir_;
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  size_t begin = 0;
  for (size_t end; (end = text.find('\n', begin)) != std::string::npos; begin = end + 1)
    lines.push_back(text.substr(begin, end - begin + 1));
  return lines;
}

TEST_F(DamagedRecording, CutMidPayloadKeepsTheCompleteFrames) {
  // The writer was appending frame 2: half its pixels written, its metadata line not yet.
  fs::resize_file(path("frames.bin"), 2 * kFrameBytes + 100);
  const auto lines = lines_of(read_file(path("frames.jsonl")));
  write_file(path("frames.jsonl"), lines[0] + lines[1]);
  RecordingReader reader(dir_);
  EXPECT_EQ(reader.frame_count(), 2u);
  ASSERT_FALSE(reader.warnings().empty());
  EXPECT_TRUE(contains(reader.warnings()[0], "frames.bin")) << reader.warnings()[0];
  EXPECT_EQ(reader.ground_truth().size(), 2u);
  Frame frame;
  reader.read(1, frame);  // the complete frames still pass their checksum
}

TEST_F(DamagedRecording, MetadataPointingPastTheEndOfThePayloadsDropsThoseFrames) {
  // Out-of-order persistence after a power loss: the metadata line made it, the pixels did not.
  fs::resize_file(path("frames.bin"), 2 * kFrameBytes + 7);
  RecordingReader reader(dir_);
  EXPECT_EQ(reader.frame_count(), 2u);
  EXPECT_EQ(reader.ground_truth().size(), 2u);
  ASSERT_FALSE(reader.warnings().empty());
  EXPECT_TRUE(contains(reader.warnings()[0], "ends at byte 1031 inside frame 2 (bytes 1024 to 1536)"))
      << reader.warnings()[0];
}

TEST_F(DamagedRecording, CutMidMetadataLine) {
  const std::string text = read_file(path("frames.jsonl"));
  const auto lines = lines_of(text);
  write_file(path("frames.jsonl"), lines[0] + lines[1] + lines[2].substr(0, 40));
  RecordingReader reader(dir_);
  EXPECT_EQ(reader.frame_count(), 2u);
  ASSERT_FALSE(reader.warnings().empty());
  EXPECT_TRUE(contains(reader.warnings()[0], "frames.jsonl line 3: cut off after 40 bytes")) << reader.warnings()[0];
}

TEST_F(DamagedRecording, MissingFinalNewlineKeepsTheCompleteLine) {
  // Only the newline of the last line is missing: the line is whole, so its frame is kept.
  const std::string text = read_file(path("frames.jsonl"));
  write_file(path("frames.jsonl"), text.substr(0, text.size() - 1));
  RecordingReader reader(dir_);
  EXPECT_EQ(reader.frame_count(), 3u);
  ASSERT_EQ(reader.warnings().size(), 1u);
  EXPECT_TRUE(contains(reader.warnings()[0], "frames.jsonl line 3: no final newline")) << reader.warnings()[0];
}

TEST_F(DamagedRecording, CutGroundTruthDropsTheFramesWithoutIt) {
  const auto lines = lines_of(read_file(path("ground_truth.jsonl")));
  write_file(path("ground_truth.jsonl"), lines[0] + lines[1].substr(0, 10));
  RecordingReader reader(dir_);
  EXPECT_EQ(reader.frame_count(), 1u);
  EXPECT_EQ(reader.ground_truth().size(), 1u);
  EXPECT_FALSE(reader.warnings().empty());
}

// Simulates a crash at every n-th byte of the writer's output stream (payload, ground-truth line,
// metadata line per frame, in that order) and checks that the frames whose metadata line was
// complete (the newline aside) are exactly the ones that open.
TEST_F(DamagedRecording, CutAtAnyByteOfTheAppendStream) {
  log::set_max_level(log::Level::Error);  // hundreds of expected warnings
  const std::string frames = read_file(path("frames.bin"));
  const auto metadata = lines_of(read_file(path("frames.jsonl")));
  const auto truth = lines_of(read_file(path("ground_truth.jsonl")));
  struct Piece {
    const char* file;
    size_t file_offset;
    size_t size;
  };
  std::vector<Piece> stream;
  size_t meta_at = 0, truth_at = 0;
  for (size_t i = 0; i < 3; ++i) {
    stream.push_back({"frames.bin", i * kFrameBytes, kFrameBytes});
    stream.push_back({"ground_truth.jsonl", truth_at, truth[i].size()});
    truth_at += truth[i].size();
    stream.push_back({"frames.jsonl", meta_at, metadata[i].size()});
    meta_at += metadata[i].size();
  }
  const std::string originals[3] = {frames, read_file(path("ground_truth.jsonl")), read_file(path("frames.jsonl"))};
  const char* names[3] = {"frames.bin", "ground_truth.jsonl", "frames.jsonl"};
  size_t total = 0;
  for (const auto& p : stream) total += p.size;

  // Every 37th byte, and the bytes around the end of every piece (where lines lose their newline).
  std::vector<size_t> cuts;
  for (size_t cut = 0; cut <= total; cut += 37) cuts.push_back(cut);
  std::vector<size_t> frame_ends{0};
  size_t end = 0;
  for (size_t k = 0; k < stream.size(); ++k) {
    end += stream[k].size;
    for (size_t d : {end - 2, end - 1, end, end + 1})
      if (d <= total) cuts.push_back(d);
    if (k % 3 == 2) frame_ends.push_back(end);
  }
  for (size_t cut : cuts) {
    size_t length[3] = {0, 0, 0};
    size_t complete_frames = 0, consumed = 0;
    for (size_t k = 0; k < stream.size(); ++k) {
      const Piece& p = stream[k];
      const size_t taken = std::min(p.size, cut > consumed ? cut - consumed : 0);
      const int f = std::string(p.file) == "frames.bin" ? 0 : std::string(p.file) == "ground_truth.jsonl" ? 1 : 2;
      if (taken > 0) length[f] = p.file_offset + taken;
      if (f == 2 && taken >= p.size - 1) ++complete_frames;  // the newline alone may be missing
      consumed += p.size;
    }
    for (int f = 0; f < 3; ++f) write_file(path(names[f]), originals[f].substr(0, length[f]));
    RecordingReader reader(dir_);
    EXPECT_EQ(reader.frame_count(), complete_frames) << "cut at byte " << cut;
    EXPECT_EQ(reader.ground_truth().size(), complete_frames) << "cut at byte " << cut;
    // Between two appends nothing is cut off, so there is nothing to warn about.
    const bool between_appends = std::find(frame_ends.begin(), frame_ends.end(), cut) != frame_ends.end();
    EXPECT_EQ(reader.warnings().empty(), between_appends) << "cut at byte " << cut;
    for (size_t i = 0; i < reader.frame_count(); ++i) {
      Frame frame;
      reader.read(i, frame);  // throws if a kept frame were incomplete
    }
  }
  log::set_max_level(log::Level::Info);
}

TEST_F(DamagedRecording, CorruptMetadataLineInTheMiddle) {
  const auto lines = lines_of(read_file(path("frames.jsonl")));
  write_file(path("frames.jsonl"), lines[0] + "{\"index\":1,\"offset\":5x12}\n" + lines[2]);
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, (dir_ / "frames.jsonl").string() + " line 2: invalid JSON at byte")) << message;
}

TEST_F(DamagedRecording, CorruptLastLineWithItsNewlineIsAnError) {
  const auto lines = lines_of(read_file(path("frames.jsonl")));
  write_file(path("frames.jsonl"), lines[0] + lines[1] + "garbage\n");
  EXPECT_TRUE(contains(open_error(), "frames.jsonl line 3: invalid JSON"));
}

TEST_F(DamagedRecording, MissingMetadataField) {
  edit("frames.jsonl", ",\"exposure_ns\":8000001", "");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "frames.jsonl line 2: missing field \"exposure_ns\" (integer nanoseconds)")) << message;
}

TEST_F(DamagedRecording, WrongTypeOfMetadataField) {
  edit("frames.jsonl", "\"readout_ns\":12345678", "\"readout_ns\":\"12345678\"");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "frames.jsonl line 1: field \"readout_ns\" is \"12345678\", expected integer"))
      << message;
}

TEST_F(DamagedRecording, UnknownTimestampMeaning) {
  edit("frames.jsonl", "end_of_frame", "end_of_world");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "frames.jsonl line 1: raw_timestamp_meaning is \"end_of_world\"")) << message;
}

TEST_F(DamagedRecording, FrameSizeDisagreesWithTheImageSize) {
  edit("frames.jsonl", "\"size\":512", "\"size\":500");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "frames.jsonl line 1: size 500, expected 512 (one 32x16 GREY image")) << message;
}

TEST_F(DamagedRecording, FramesOutOfOrder) {
  edit("frames.jsonl", "\"index\":1", "\"index\":2");
  EXPECT_TRUE(contains(open_error(), "frames.jsonl line 2: index 2, expected 1"));
}

TEST_F(DamagedRecording, PayloadOffsetsWithAGap) {
  edit("frames.jsonl", "\"offset\":1024", "\"offset\":1030");
  EXPECT_TRUE(contains(open_error(), "frames.jsonl line 3: offset 1030, expected 1024"));
}

TEST_F(DamagedRecording, ChecksumMismatchNamesTheFrameAndItsBytes) {
  std::string frames = read_file(path("frames.bin"));
  frames[kFrameBytes + 77] = char(frames[kFrameBytes + 77] ^ 0x10);
  write_file(path("frames.bin"), frames);
  RecordingReader reader(dir_);  // checksums are checked when a frame is read
  Frame frame;
  reader.read(0, frame);
  const std::string message = error_message([&] { reader.read(1, frame); });
  EXPECT_TRUE(contains(message, (dir_ / "frames.bin").string() + ": frame 1 (bytes 512 to 1024, ")) << message;
  EXPECT_TRUE(contains(message, "frames.jsonl line 2): CRC-32")) << message;
}

TEST_F(DamagedRecording, UnknownVersion) {
  edit("recording.json", "\"version\": 1", "\"version\": 2");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, (dir_ / "recording.json").string() + ": format version 2 is not supported")) << message;
}

TEST_F(DamagedRecording, NotARecordingFormat) {
  edit("recording.json", "arpipe-recording", "something-else");
  EXPECT_TRUE(contains(open_error(), "recording.json: format is \"something-else\", expected \"arpipe-recording\""));
}

TEST_F(DamagedRecording, UnsupportedPixelFormat) {
  edit("recording.json", "\"GREY\"", "\"MJPG\"");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "recording.json: pixel_format \"MJPG\" is not supported")) << message;
}

TEST_F(DamagedRecording, StrideTooSmallForTheWidth) {
  edit("recording.json", "\"bytes_per_line\": 32", "\"bytes_per_line\": 31");
  EXPECT_TRUE(contains(open_error(), "recording.json: bytes_per_line 31 does not fit 32 pixels"));
}

TEST_F(DamagedRecording, InvalidRecordingJson) {
  edit("recording.json", "\"width\": 32,", "\"width\": 32,,");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "recording.json: invalid JSON at byte")) << message;
}

TEST_F(DamagedRecording, PartNameLeavingTheDirectory) {
  edit("recording.json", "\"frames.bin\"", "\"../frames.bin\"");
  EXPECT_TRUE(contains(open_error(), "recording.json: files.frames is \"../frames.bin\""));
}

TEST_F(DamagedRecording, MissingRecordingJson) {
  fs::remove(path("recording.json"));
  EXPECT_TRUE(contains(open_error(), (dir_ / "recording.json").string() + ": missing"));
}

TEST_F(DamagedRecording, MissingDirectory) {
  fs::remove_all(dir_);
  EXPECT_TRUE(contains(open_error(), dir_.string() + ": not a recording (no such directory)"));
}

TEST_F(DamagedRecording, MissingCameraModel) {
  fs::remove(path("camera.cameramodel"));
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, (dir_ / "camera.cameramodel").string() + ": missing")) << message;
}

TEST_F(DamagedRecording, CorruptCameraModel) {
  write_file(path("camera.cameramodel"), "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [ 1, 2 ");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "camera.cameramodel")) << message;
}

TEST_F(DamagedRecording, CameraModelOfAnotherImageSize) {
  fs::remove(path("camera.cameramodel"));
  small_camera(64, 16).save(path("camera.cameramodel"));
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "camera.cameramodel: imager size 64x16 differs from the frame size 32x16")) << message;
}

TEST_F(DamagedRecording, MissingFramesFile) {
  fs::remove(path("frames.bin"));
  EXPECT_TRUE(contains(open_error(), (dir_ / "frames.bin").string() + ": missing"));
}

TEST_F(DamagedRecording, MissingMetadataFile) {
  fs::remove(path("frames.jsonl"));
  EXPECT_TRUE(contains(open_error(), (dir_ / "frames.jsonl").string() + ": missing"));
}

TEST_F(DamagedRecording, CorruptGroundTruthLine) {
  edit("ground_truth.jsonl", "\"T_cam_world_mid\":{\"r\":[", "\"T_cam_world_mid\":{\"r\":[\"x\",");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "ground_truth.jsonl line 1 (in \"T_cam_world_mid\"): field \"r\"")) << message;
}

TEST_F(DamagedRecording, GroundTruthOfAnotherFrame) {
  edit("ground_truth.jsonl", "\"sequence\":102", "\"sequence\":103");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, "ground_truth.jsonl line 2: sequence 103 differs from frame 1's sequence 102"))
      << message;
}

}  // namespace
}  // namespace arpipe
