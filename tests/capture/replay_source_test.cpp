// ReplaySource: order, end of stream, looping with time kept increasing, real-time pacing (a
// lower bound only), interrupt, damaged frames skipped, camera-model override checks.
#include "capture/replay_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "capture/recording/recording_reader.h"
#include "capture_test_support.h"

namespace arpipe {
namespace {

using namespace arpipe::test;

SourceConfig replay_config(const fs::path& dir, ReplayPacing pacing = ReplayPacing::Fast, bool loop = false) {
  SourceConfig c;
  c.path = dir;
  c.pacing = pacing;
  c.loop = loop;
  return c;
}

// A GREY recording whose frames start exposing at the given times (ns); each frame's pixels hold its index.
void write_timed_recording(const fs::path& dir, const std::vector<int64_t>& starts_ns, int64_t frame_duration_ns) {
  RecordingInfo info;
  info.pixel_format = PixelFormat::GREY;
  info.width = 8;
  info.height = 4;
  RecordingWriter writer(dir, info, small_camera(8, 4));
  for (size_t i = 0; i < starts_ns.size(); ++i) {
    Frame f = Frame::allocate(PixelFormat::GREY, 8, 4);
    std::fill(f.data.begin(), f.data.end(), uint8_t(i));
    f.meta.sequence = i;
    f.meta.exposure_start_ns = starts_ns[i];
    f.meta.exposure_ns = 1'000'000;
    f.meta.frame_duration_ns = frame_duration_ns;
    f.meta.raw_timestamp_ns = starts_ns[i];
    writer.append(f);
  }
}

TEST(ReplaySource, FastDeliversEveryFrameInOrderThenEnds) {
  const fs::path dir = scratch_dir("replay-fast");
  write_recording(dir, PixelFormat::YUYV, 16, 8, 5);
  RecordingReader reader(dir);
  ReplaySource source(replay_config(dir));
  EXPECT_FALSE(source.is_live());
  ASSERT_NE(source.camera_model(), nullptr);
  EXPECT_EQ(source.camera_model()->intrinsics(), reader.camera_model().intrinsics());
  for (size_t i = 0; i < 5; ++i) {
    Frame frame;
    ASSERT_EQ(source.next(frame), SourceStatus::Frame) << i;
    Frame expected;
    reader.read(i, expected);
    EXPECT_EQ(frame.data, expected.data) << i;
    EXPECT_EQ(frame.meta.sequence, expected.meta.sequence);
    EXPECT_EQ(frame.meta.exposure_start_ns, expected.meta.exposure_start_ns);
  }
  Frame frame;
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

TEST(ReplaySource, TimestampOffsetIsAddedAndRecorded) {
  const fs::path dir = scratch_dir("replay-offset");
  write_timed_recording(dir, {1'000, 2'000}, 1'000);
  SourceConfig config = replay_config(dir);
  config.timestamp_offset_ns = 250;
  ReplaySource source(config);
  Frame frame;
  ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  EXPECT_EQ(frame.meta.exposure_start_ns, 1'250);
  EXPECT_EQ(frame.meta.timestamp_offset_ns, 250);
  EXPECT_EQ(frame.meta.raw_timestamp_ns, 1'000);  // the source's own timestamp stays as recorded
}

TEST(ReplaySource, LoopKeepsTimeAndSequenceIncreasing) {
  const fs::path dir = scratch_dir("replay-loop");
  // Three frames 10 ms apart: one pass lasts 20 ms plus one 10 ms interval.
  write_timed_recording(dir, {5'000'000, 15'000'000, 25'000'000}, 10'000'000);
  ReplaySource source(replay_config(dir, ReplayPacing::Fast, true));
  int64_t previous_time = 0;
  uint64_t previous_sequence = 0;
  for (int k = 0; k < 8; ++k) {
    Frame frame;
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    const int pass = k / 3, index = k % 3;
    EXPECT_EQ(frame.data[0], uint8_t(index));
    EXPECT_EQ(frame.meta.exposure_start_ns, 5'000'000 + index * 10'000'000 + pass * 30'000'000) << k;
    if (k > 0) {
      EXPECT_GT(frame.meta.exposure_start_ns, previous_time);
      EXPECT_EQ(frame.meta.sequence, previous_sequence + 1);  // no gap appears at the wrap
    }
    previous_time = frame.meta.exposure_start_ns;
    previous_sequence = frame.meta.sequence;
  }
}

TEST(ReplaySource, TimestampPacingNeverDeliversEarly) {
  const fs::path dir = scratch_dir("replay-paced");
  const std::vector<int64_t> starts{100'000'000, 120'000'000, 150'000'000, 160'000'000};
  write_timed_recording(dir, starts, 20'000'000);
  ReplaySource source(replay_config(dir, ReplayPacing::Timestamps));
  const auto before_first = std::chrono::steady_clock::now();
  for (size_t i = 0; i < starts.size(); ++i) {
    Frame frame;
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
    const auto elapsed = std::chrono::steady_clock::now() - before_first;
    // A lower bound only: a busy machine may deliver late, never early.
    EXPECT_GE(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count(), starts[i] - starts[0]) << i;
  }
  Frame frame;
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

TEST(ReplaySource, InterruptWakesASleepingNext) {
  const fs::path dir = scratch_dir("replay-interrupt");
  // The second frame is an hour after the first: without the interrupt this test would hang.
  write_timed_recording(dir, {0, 3'600'000'000'000}, 3'600'000'000'000);
  ReplaySource source(replay_config(dir, ReplayPacing::Timestamps));
  Frame frame;
  ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  std::thread interrupter([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    source.interrupt();
  });
  EXPECT_EQ(source.next(frame), SourceStatus::Retry);
  interrupter.join();
}

TEST(ReplaySource, InterruptBeforeNextIsNotLost) {
  const fs::path dir = scratch_dir("replay-interrupt-early");
  write_timed_recording(dir, {0, 3'600'000'000'000}, 3'600'000'000'000);
  ReplaySource source(replay_config(dir, ReplayPacing::Timestamps));
  Frame frame;
  ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  source.interrupt();  // e.g. the pipeline stops between two calls
  EXPECT_EQ(source.next(frame), SourceStatus::Retry);
}

TEST(ReplaySource, DamagedFrameIsSkippedAndCounted) {
  const fs::path dir = scratch_dir("replay-damaged");
  write_recording(dir, PixelFormat::GREY, 16, 8, 4);
  std::string frames = read_file(dir / "frames.bin");
  frames[2 * 128 + 5] = char(frames[2 * 128 + 5] ^ 1);
  write_file(dir / "frames.bin", frames);
  ReplaySource source(replay_config(dir));
  std::vector<SourceStatus> statuses;
  std::vector<uint64_t> sequences;
  for (int k = 0; k < 5; ++k) {
    Frame frame;
    statuses.push_back(source.next(frame));
    if (statuses.back() == SourceStatus::Frame) sequences.push_back(frame.meta.sequence);
  }
  EXPECT_EQ(statuses, (std::vector<SourceStatus>{SourceStatus::Frame, SourceStatus::Frame, SourceStatus::Retry,
                                                 SourceStatus::Frame, SourceStatus::EndOfStream}));
  // random_frame's sequences are 100, 102, 104, 106: frame 2 (104) is missing.
  EXPECT_EQ(sequences, (std::vector<uint64_t>{100, 102, 106}));
  EXPECT_EQ(source.frames_skipped(), 1u);
}

// Flips one byte of frame `index`'s pixels in frames.bin (GREY frames of `frame_bytes` each).
void damage_frame(const fs::path& dir, size_t index, size_t frame_bytes) {
  std::string frames = read_file(dir / "frames.bin");
  frames[index * frame_bytes + 5] = char(frames[index * frame_bytes + 5] ^ 1);
  write_file(dir / "frames.bin", frames);
}

// What a looped replay delivers over three passes of a 4-frame recording, damaged on disk after
// the first pass: each frame's first pixel (-1: skipped).
std::vector<int> three_passes_damaged_after_the_first(const fs::path& dir, int loop_cache_mb, uint64_t& skipped) {
  SourceConfig config = replay_config(dir, ReplayPacing::Fast, true);
  config.loop_cache_mb = loop_cache_mb;
  ReplaySource source(config);
  std::vector<int> got;
  for (int k = 0; k < 12; ++k) {
    if (k == 4) damage_frame(dir, 1, 128);
    Frame frame;
    got.push_back(source.next(frame) == SourceStatus::Frame ? int(frame.meta.sequence) : -1);
  }
  skipped = source.frames_skipped();
  return got;
}

// source.loop_cache_mb: a looped recording that fits is read and checked on its first pass only;
// later passes are the frames that pass delivered (a change to the file is not seen). Over the
// budget, or with 0, every pass reads and checks the file: the damage is seen and counted.
TEST(ReplaySource, ALoopedRecordingThatFitsIsReadAndCheckedOnce) {
  // random_frame's sequences are 100, 102, 104, 106; a pass adds 7 (the span plus one).
  const std::vector<int> clean{100, 102, 104, 106, 107, 109, 111, 113, 114, 116, 118, 120};
  uint64_t skipped = 0;
  const fs::path cached = scratch_dir("replay-loop-cache");
  write_recording(cached, PixelFormat::GREY, 16, 8, 4);
  EXPECT_EQ(three_passes_damaged_after_the_first(cached, 1, skipped), clean);
  EXPECT_EQ(skipped, 0u);

  const std::vector<int> damaged{100, 102, 104, 106, 107, -1, 111, 113, 114, -1, 118, 120};
  const fs::path uncached = scratch_dir("replay-loop-uncached");
  write_recording(uncached, PixelFormat::GREY, 16, 8, 4);
  EXPECT_EQ(three_passes_damaged_after_the_first(uncached, 0, skipped), damaged);
  EXPECT_EQ(skipped, 2u);
}

TEST(ReplaySource, ALoopedRecordingOverTheBudgetIsReadEveryPass) {
  const fs::path dir = scratch_dir("replay-loop-over-budget");
  write_recording(dir, PixelFormat::GREY, 1024, 512, 3);  // 1.5 MiB of frames
  SourceConfig config = replay_config(dir, ReplayPacing::Fast, true);
  config.loop_cache_mb = 1;
  ReplaySource source(config);
  for (int k = 0; k < 3; ++k) {
    Frame frame;
    ASSERT_EQ(source.next(frame), SourceStatus::Frame);
  }
  damage_frame(dir, 0, 1024 * 512);
  Frame frame;
  EXPECT_EQ(source.next(frame), SourceStatus::Retry) << "read from the file again";
  EXPECT_EQ(source.frames_skipped(), 1u);
}

// A frame damaged from the start is skipped on every pass, cached or not.
TEST(ReplaySource, AFrameDamagedFromTheStartIsSkippedOnEveryPass) {
  const fs::path dir = scratch_dir("replay-loop-damaged");
  write_recording(dir, PixelFormat::GREY, 16, 8, 4);
  damage_frame(dir, 2, 128);
  ReplaySource source(replay_config(dir, ReplayPacing::Fast, true));
  std::vector<int> got;
  for (int k = 0; k < 8; ++k) {
    Frame frame;
    got.push_back(source.next(frame) == SourceStatus::Frame ? int(frame.meta.sequence) : -1);
  }
  EXPECT_EQ(got, (std::vector<int>{100, 102, -1, 106, 107, 109, -1, 113}));
  EXPECT_EQ(source.frames_skipped(), 2u);
}

TEST(ReplaySource, CameraModelOverrideOfTheSameSizeIsUsed) {
  const fs::path dir = scratch_dir("replay-override");
  write_recording(dir, PixelFormat::GREY, 16, 8, 1);
  const CameraModel other = CameraModel::pinhole(20, 21, 7.5, 3.5, 16, 8);
  other.save(dir.parent_path() / "override-ok.cameramodel");
  SourceConfig config = replay_config(dir);
  config.camera_model = dir.parent_path() / "override-ok.cameramodel";
  ReplaySource source(config);
  EXPECT_EQ(source.camera_model()->intrinsics(), other.intrinsics());
}

TEST(ReplaySource, CameraModelOverrideOfAnotherSizeIsRefused) {
  const fs::path dir = scratch_dir("replay-override-size");
  write_recording(dir, PixelFormat::GREY, 16, 8, 1);
  const fs::path model_path = dir.parent_path() / "override-wrong.cameramodel";
  fs::remove(model_path);
  CameraModel::pinhole(20, 20, 15.5, 7.5, 32, 16).save(model_path);
  SourceConfig config = replay_config(dir);
  config.camera_model = model_path;
  const std::string message = error_message<CameraModelError>([&] { ReplaySource source(config); });
  EXPECT_NE(message.find(model_path.string() + ": imager size 32x16 differs from the 16x8 frames"), std::string::npos)
      << message;
}

TEST(ReplaySource, MissingRecordingIsARecordingError) {
  const fs::path dir = scratch_dir("replay-missing") / "nothing-here";
  const std::string message = error_message([&] { ReplaySource source(replay_config(dir)); });
  EXPECT_NE(message.find(dir.string()), std::string::npos) << message;
}

TEST(ReplaySource, EmptyRecordingEndsAtOnce) {
  const fs::path dir = scratch_dir("replay-empty");
  write_recording(dir, PixelFormat::GREY, 16, 8, 0);
  ReplaySource source(replay_config(dir, ReplayPacing::Timestamps, true));
  Frame frame;
  EXPECT_EQ(source.next(frame), SourceStatus::EndOfStream);
}

}  // namespace
}  // namespace arpipe
