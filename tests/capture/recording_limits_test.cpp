// Recording inputs of issue 18: a huge metadata line is refused at the line limit, the parts must
// be regular files (a FIFO as frames.bin used to block open() forever), a symlink loop or an empty
// path is named, declared frame sizes and timestamps are checked arithmetic, and the replay
// source names source.path and source.timestamp_offset_ns.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <future>
#include <limits>

#include "capture/recording/recording_reader.h"
#include "capture/replay_source.h"
#include "capture_test_support.h"
#include "core/config/config.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

constexpr int kWidth = 16, kHeight = 8;  // GREY: 128 bytes per frame

class RecordingLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch_dir(std::string("limits-") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    write_recording(dir_, PixelFormat::GREY, kWidth, kHeight, 3);
  }
  std::string open_error() const {
    return error_message([&] { RecordingReader reader(dir_); });
  }
  // Opening must not block: a FIFO without a writer used to hang in open().
  std::string open_error_within_seconds(int seconds, const fs::path& fifo) const {
    auto opening = std::async(std::launch::async, [&] { return open_error(); });
    if (opening.wait_for(std::chrono::seconds(seconds)) != std::future_status::ready) {
      const int writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // lets the blocked open() go
      ADD_FAILURE() << "opening the recording blocked on " << fifo;
      opening.wait();
      if (writer >= 0) ::close(writer);
      return "";
    }
    return opening.get();
  }
  static bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  }
  fs::path dir_;
};

TEST_F(RecordingLimits, AHugeMetadataLineIsRefusedAtTheLineLimit) {
  // Before: the whole 200 KB (or 200 MB) line was read into memory and handed to the JSON parser.
  std::string text = read_file(dir_ / "frames.jsonl");
  text.insert(text.find('\n') + 1, std::string(200 * 1024, ' ') + "{}\n");
  write_file(dir_ / "frames.jsonl", text);
  EXPECT_EQ(open_error(), (dir_ / "frames.jsonl").string() + " line 2: longer than the limit of 65536 bytes for one line");
}

TEST_F(RecordingLimits, AFifoAsFramesBinIsRefusedAtOnce) {
  fs::remove(dir_ / "frames.bin");
  ASSERT_EQ(::mkfifo((dir_ / "frames.bin").c_str(), 0600), 0);
  const std::string message = open_error_within_seconds(5, dir_ / "frames.bin");
  EXPECT_EQ(message, (dir_ / "frames.bin").string() +
                         ": cannot read recording file: it is a FIFO (named pipe), expected a regular file");
}

TEST_F(RecordingLimits, AFifoAsFramesJsonlIsRefusedAtOnce) {
  fs::remove(dir_ / "frames.jsonl");
  ASSERT_EQ(::mkfifo((dir_ / "frames.jsonl").c_str(), 0600), 0);
  const std::string message = open_error_within_seconds(5, dir_ / "frames.jsonl");
  EXPECT_TRUE(contains(message, (dir_ / "frames.jsonl").string() + ": cannot read recording file: it is a FIFO"))
      << message;
}

TEST_F(RecordingLimits, ASymlinkLoopAndAnEmptyPathAreNamed) {
  const fs::path loop = scratch_dir("limits-loop") / "a";
  fs::create_symlink(loop.parent_path() / "b", loop);
  fs::create_symlink(loop, loop.parent_path() / "b");
  // Before: std::filesystem's raw "filesystem error: status: Too many levels of symbolic links [...]".
  EXPECT_EQ(error_message([&] { RecordingReader reader(loop); }),
            loop.string() + ": Too many levels of symbolic links (the recording directory)");
  EXPECT_EQ(error_message([&] { RecordingReader reader(""); }), "not a recording: the directory's path is empty");
}

TEST_F(RecordingLimits, ADeclaredFrameOverTheLimitIsRefused) {
  // 16384 x 16384 RGB24 with 16 times the minimum stride: 12.9 GB a frame, from a 400-byte file.
  std::string info = read_file(dir_ / "recording.json");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"\"GREY\"", "\"RGB24\""},
           {fmt::format("\"width\": {}", kWidth), "\"width\": 16384"},
           {fmt::format("\"height\": {}", kHeight), "\"height\": 16384"},
           {fmt::format("\"bytes_per_line\": {}", kWidth), "\"bytes_per_line\": 786432"}}) {
    const size_t at = info.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    info.replace(at, from.size(), to);
  }
  write_file(dir_ / "recording.json", info);
  EXPECT_EQ(open_error(), (dir_ / "recording.json").string() +
                              ": a 16384x16384 RGB24 frame with 786432 bytes per line exceeds the limit of 1073741824 "
                              "bytes per frame");
}

TEST_F(RecordingLimits, TimestampsThatOverflowAreRefusedWithTheLine) {
  std::string text = read_file(dir_ / "frames.jsonl");
  const std::string from = "\"exposure_start_ns\":";
  const size_t at = text.find(from, text.find('\n') + 1);  // line 2
  const size_t end = text.find(',', at);
  text.replace(at, end - at, from + std::to_string(std::numeric_limits<int64_t>::max() - 5));
  write_file(dir_ / "frames.jsonl", text);
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, (dir_ / "frames.jsonl").string() + " line 2: exposure_start_ns 9223372036854775802 + "
                                                                   "exposure_ns"))
      << message;
  EXPECT_TRUE(contains(message, "overflows 64-bit nanoseconds")) << message;
}

TEST_F(RecordingLimits, ANumberNoDoubleHoldsIsARecordingError) {
  // tests/fuzz/regressions/fuzz_recording/info-number-overflow-5e308: nlohmann's out_of_range
  // escaped as an exception that was not a RecordingError.
  write_file(dir_ / "recording.json", "5e308");
  const std::string message = open_error();
  EXPECT_TRUE(contains(message, (dir_ / "recording.json").string() + ": invalid JSON (the recording description "
                                                                     "expected): "))
      << message;
  EXPECT_TRUE(contains(message, "number overflow")) << message;
}

TEST_F(RecordingLimits, ReplayNamesAnEmptySourcePath) {
  SourceConfig config;
  config.pacing = ReplayPacing::Fast;
  // Before: ": not a recording (no such directory)", naming nothing.
  EXPECT_EQ(error_message<ConfigError>([&] { ReplaySource source(config); }),
            "source.path is empty: a replay needs the recording directory (set source.path, or source.type for a "
            "live camera)");
  config.path = dir_ / "absent";
  EXPECT_EQ(error_message([&] { ReplaySource source(config); }),
            (dir_ / "absent").string() + ": not a recording (no such directory) (source.path)");
}

TEST_F(RecordingLimits, ATimestampOffsetThatOverflowsIsRefusedAtStart) {
  // A recording whose times lie near the top of int64 (valid on their own) and an offset that
  // pushes them past it: before, exposure_start_ns wrapped to a large negative time.
  std::string text = read_file(dir_ / "frames.jsonl");
  std::string out;
  int64_t start = std::numeric_limits<int64_t>::max() - 3'000'000'000;
  for (size_t begin = 0, end; (end = text.find('\n', begin)) != std::string::npos; begin = end + 1) {
    std::string line = text.substr(begin, end - begin + 1);
    const std::string from = "\"exposure_start_ns\":";
    const size_t at = line.find(from);
    line.replace(at, line.find(',', at) - at, from + std::to_string(start));
    start += 33'000'000;
    out += line;
  }
  write_file(dir_ / "frames.jsonl", out);
  SourceConfig config;
  config.path = dir_;
  config.pacing = ReplayPacing::Fast;
  ReplaySource{config};  // without an offset the recording replays
  config.timestamp_offset_ns = 3'600'000'000'000;
  const std::string message = error_message<ConfigError>([&] { ReplaySource source(config); });
  EXPECT_TRUE(contains(message, "source.timestamp_offset_ns 3600000000000 added to the exposure start")) << message;
  EXPECT_TRUE(contains(message, "overflows 64-bit nanoseconds")) << message;
}

}  // namespace
}  // namespace arpipe
