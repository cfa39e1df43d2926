// The recording sink never overwrites a recording (issue 18, finding 10): a path that already
// holds one fails setup, with the path and the config key, instead of a log line at the first frame.
#include <gtest/gtest.h>

#include "capture/sinks/recording_sink.h"
#include "capture_test_support.h"
#include "sink_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

TEST(RecordingSinkSetup, AnExistingRecordingFailsSetupNamingThePathAndTheConfigKey) {
  const fs::path dir = scratch_dir("recording-exists") / "composited";
  write_recording(dir, PixelFormat::RGB24, 8, 6, 2);
  const std::string before = read_file(dir / "frames.jsonl");
  const std::string message =
      error_message<std::runtime_error>([&] { RecordingSink sink(RecordingSinkConfig{true, dir}); });
  EXPECT_NE(message.find(dir.string() + " (config sinks.recording.path): already holds a recording"),
            std::string::npos)
      << message;
  EXPECT_EQ(read_file(dir / "frames.jsonl"), before);
}

TEST(RecordingSinkSetup, APartOfARecordingFailsSetupToo) {
  const fs::path dir = scratch_dir("recording-part") / "composited";
  fs::create_directories(dir);
  write_file(dir / "frames.bin", "frames of a recording whose recording.json was lost");
  const std::string message =
      error_message<std::runtime_error>([&] { RecordingSink sink(RecordingSinkConfig{true, dir}); });
  EXPECT_NE(message.find("sinks.recording.path"), std::string::npos) << message;
  EXPECT_NE(message.find("frames.bin"), std::string::npos) << message;
}

TEST(RecordingSinkSetup, AFileInTheWayFailsSetup) {
  const fs::path path = scratch_dir("recording-file") / "composited";
  write_file(path, "not a directory");
  const std::string message =
      error_message<std::runtime_error>([&] { RecordingSink sink(RecordingSinkConfig{true, path}); });
  EXPECT_NE(message.find(path.string() + " (config sinks.recording.path): exists and is not a directory"),
            std::string::npos)
      << message;
}

TEST(RecordingSinkSetup, AnEmptyDirectoryIsFine) {
  const fs::path dir = scratch_dir("recording-empty") / "composited";
  fs::create_directories(dir);
  EXPECT_NO_THROW(RecordingSink sink(RecordingSinkConfig{true, dir}));
}

}  // namespace
}  // namespace arpipe
