// Outputs of an earlier run are replaced only once the new run is up (issue 18, finding 5): a sink
// writes under a temporary name beside its file and renames it over the old one at the run's start
// (run_started, the first frame or a flush); one destroyed before that leaves the old file as it was.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "capture/sinks/output_path.h"
#include "capture/sinks/png_sink.h"
#include "capture/sinks/results_sink.h"
#include "capture/sinks/y4m_sink.h"
#include "capture_test_support.h"
#include "sink_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

const std::string kPrevious = "the previous run's output\n";

// A pid that ran and has ended (for a temporary left by a crashed run).
pid_t ended_pid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, nullptr, 0);
  return pid;
}

TEST(SinkReplace, SinksDestroyedBeforeTheRunStartsLeaveThePreviousOutputsUntouched) {
  const fs::path dir = scratch_dir("replace-failed-start");
  write_file(dir / "results.jsonl", kPrevious);
  write_file(dir / "video.y4m", kPrevious);
  {
    ResultsSink results(ResultsSinkConfig{true, dir / "results.jsonl"});
    Y4mSink y4m(Y4mSinkConfig{true, dir / "video.y4m"});
    // A setup step after the sinks fails here (a bad mesh): nothing was consumed, nothing flushed.
  }
  EXPECT_EQ(read_file(dir / "results.jsonl"), kPrevious);
  EXPECT_EQ(read_file(dir / "video.y4m"), kPrevious);
  EXPECT_EQ(directory_names(dir), (std::vector<std::string>{"results.jsonl", "video.y4m"})) << "a temporary was left";
}

TEST(SinkReplace, TheFirstFrameReplacesThePreviousOutputs) {
  const fs::path dir = scratch_dir("replace-first-frame");
  write_file(dir / "results.jsonl", kPrevious);
  write_file(dir / "video.y4m", kPrevious);
  const FrameContext frame = sink_context(8, 6, 0);
  {
    ResultsSink results(ResultsSinkConfig{true, dir / "results.jsonl"});
    Y4mSink y4m(Y4mSinkConfig{true, dir / "video.y4m"});
    EXPECT_EQ(read_file(dir / "results.jsonl"), kPrevious) << "replaced before the run was up";
    EXPECT_EQ(read_file(dir / "video.y4m"), kPrevious) << "replaced before the run was up";
    results.consume(frame);
    y4m.consume(frame);
    // Written as the frame left the sinks, not at the end of the run.
    EXPECT_EQ(read_file(dir / "results.jsonl"), ResultsSink::to_json_line(frame) + "\n");
    EXPECT_EQ(parse_y4m_stream(read_file(dir / "video.y4m"), 8, 6).frames.size(), 1u);
  }
  EXPECT_EQ(read_file(dir / "results.jsonl"), ResultsSink::to_json_line(frame) + "\n");
  const Y4mStream video = parse_y4m_stream(read_file(dir / "video.y4m"), 8, 6);
  EXPECT_EQ(video.frames.size(), 1u);
  EXPECT_EQ(video.torn_tail_bytes, 0u);
  EXPECT_EQ(directory_names(dir), (std::vector<std::string>{"results.jsonl", "video.y4m"}));
}

// The runner says when the run is up; a run that is up but has no frames yet (or ends without
// any) replaces the previous outputs too, with its own empty ones.
TEST(SinkReplace, RunStartedOrAFlushReplacesThePreviousOutputsWithoutAFrame) {
  const fs::path dir = scratch_dir("replace-run-started");
  write_file(dir / "results.jsonl", kPrevious);
  write_file(dir / "video.y4m", kPrevious);
  {
    ResultsSink results(ResultsSinkConfig{true, dir / "results.jsonl"});
    Y4mSink y4m(Y4mSinkConfig{true, dir / "video.y4m"});
    results.run_started();
    y4m.flush();
    EXPECT_EQ(read_file(dir / "results.jsonl"), "");
    EXPECT_EQ(read_file(dir / "video.y4m"), "");
  }
  EXPECT_EQ(directory_names(dir), (std::vector<std::string>{"results.jsonl", "video.y4m"}));
}

TEST(SinkReplace, ASymlinkedOutputReplacesTheFileItPointsTo) {
  const fs::path dir = scratch_dir("replace-symlink");
  fs::create_directories(dir / "real");
  write_file(dir / "real" / "results.jsonl", kPrevious);
  fs::create_symlink("real/results.jsonl", dir / "results.jsonl");
  const FrameContext frame = sink_context(2, 2, 0);
  {
    ResultsSink results(ResultsSinkConfig{true, dir / "results.jsonl"});
    results.consume(frame);
  }
  EXPECT_TRUE(fs::is_symlink(dir / "results.jsonl"));
  EXPECT_EQ(read_file(dir / "real" / "results.jsonl"), ResultsSink::to_json_line(frame) + "\n");
  EXPECT_EQ(directory_names(dir / "real"), std::vector<std::string>{"results.jsonl"});
}

// A device (or a FIFO) is written directly: there is nothing to replace, and no temporary may go
// into /dev.
TEST(SinkReplace, ADeviceIsWrittenDirectly) {
  {
    ResultsSink results(ResultsSinkConfig{true, "/dev/null"});
    Y4mSink y4m(Y4mSinkConfig{true, "/dev/null"});
    EXPECT_FALSE(fs::exists(temporary_name("/dev/null")));
    results.consume(sink_context(2, 2, 0));
    y4m.consume(sink_context(2, 2, 0));
    EXPECT_EQ(results.failures() + y4m.failures(), 0u);
  }
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

// A temporary left by a run that crashed (kill -9 before its first frame) is removed by the next
// one; a temporary of a process that still runs, and other hidden files, are not.
TEST(SinkReplace, TemporariesOfEndedRunsAreRemoved) {
  const fs::path dir = scratch_dir("replace-stale");
  const pid_t ended = ended_pid();
  const std::string stale_results = fmt::format(".results.jsonl.new-{}", ended);
  const std::string stale_png = fmt::format(".frame_000003.png.new-{}", ended);
  const std::string running = fmt::format(".results.jsonl.new-{}", getppid());
  const std::string unrelated = fmt::format(".notes.txt.new-{}", ended);
  for (const auto& name : {stale_results, running, unrelated}) write_file(dir / name, "x");
  fs::create_directories(dir / "png");
  write_file(dir / "png" / stale_png, "x");
  {
    ResultsSink results(ResultsSinkConfig{true, dir / "results.jsonl"});
    PngSink png(PngSinkConfig{true, dir / "png", 1});
    results.run_started();
  }
  auto expected = std::vector<std::string>{running, unrelated, "png", "results.jsonl"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(directory_names(dir), expected);
  EXPECT_EQ(directory_names(dir / "png"), std::vector<std::string>{});
}

}  // namespace
}  // namespace arpipe
