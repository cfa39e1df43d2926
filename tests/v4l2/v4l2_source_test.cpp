// The V4L2 source through the stand-in: negotiation, exact timestamps and exposure, MJPEG, drops,
// faults and recovery. The stand-in serves recordings; the answers come from those recordings.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <thread>

#include "capture/live/live_source.h"
#include "capture/v4l2/v4l2_stream.h"
#include "core/pipeline/pipeline_runner.h"
#include "core/image/pixel_convert.h"
#include "standin_fixture.h"

namespace arpipe {
namespace {

using test::kStandinDevice;
namespace fs = std::filesystem;

fs::path default_capture() { return fs::path(ARPIPE_BINARY_DIR) / "default-capture"; }

// V4L2 buffers carry a struct timeval: timestamps are exact to the microsecond, truncated.
int64_t to_microseconds(int64_t ns) { return ns / 1000 * 1000; }

SourceConfig v4l2_config(const std::string& device = kStandinDevice) {
  SourceConfig c;
  c.type = SourceType::V4l2;
  c.device = device;
  c.frame_timeout_ms = 1000;
  c.reconnect_min_ms = 20;
  c.reconnect_max_ms = 200;
  return c;
}

// Pulls frames until `count` arrived or `max_calls` calls were made.
std::vector<Frame> take_frames(LiveSource& source, size_t count, int max_calls = 400) {
  std::vector<Frame> frames;
  for (int i = 0; i < max_calls && frames.size() < count; ++i) {
    Frame frame;
    if (source.next(frame) == SourceStatus::Frame) frames.push_back(std::move(frame));
  }
  return frames;
}

TEST(V4L2Source, NegotiatesWhatTheConfigAsks) {
  const auto dir = test::v4l2_scratch("negotiate");
  test::StandinDevice device(dir, default_capture(), "formats = [\"native\", \"MJPG\"]\npacing = \"fast\"");
  auto config = v4l2_config();
  config.width = 640;
  config.height = 480;
  config.fps = 30;
  config.pixel_format = CaptureFormat::YUYV;
  auto source = make_live_source(config);
  EXPECT_EQ(source->format().format, PixelFormat::YUYV);
  EXPECT_EQ(source->format().width, 640);
  EXPECT_EQ(source->format().height, 480);
  // The recording's 33 333 333 ns interval, as the driver's fraction gives it back.
  ASSERT_TRUE(source->frame_interval_ns());
  EXPECT_NEAR(double(*source->frame_interval_ns()), 33'333'333.0, 1.0);
  EXPECT_TRUE(source->is_live());
}

TEST(V4L2Source, RefusesWhatTheCameraCannotDoAndListsWhatItOffers) {
  const auto dir = test::v4l2_scratch("refuse");
  test::StandinDevice device(dir, default_capture(), "formats = [\"native\", \"MJPG\"]");
  for (const auto& [width, height, fps, format] :
       {std::tuple{1280, 720, 0.0, CaptureFormat::Auto}, std::tuple{640, 480, 60.0, CaptureFormat::Auto},
        std::tuple{640, 480, 0.0, CaptureFormat::NV12}}) {
    auto config = v4l2_config();
    config.width = width;
    config.height = height;
    config.fps = fps;
    config.pixel_format = format;
    try {
      make_live_source(config);
      ADD_FAILURE() << "accepted " << width << "x" << height << " " << fps << " fps "
                    << choice_name(kCaptureFormatNames, format);
    } catch (const CameraError& e) {
      EXPECT_EQ(e.kind(), CameraError::Kind::Refused);
      const std::string what = e.what();
      EXPECT_NE(what.find(kStandinDevice), std::string::npos) << what;
      EXPECT_NE(what.find("YUYV 640x480 @ 30 fps"), std::string::npos) << what;
      EXPECT_NE(what.find("MJPG 640x480 @ 30 fps"), std::string::npos) << what;
    }
  }
}

TEST(V4L2Source, MissingDeviceIsAClearMissingError) {
  auto config = v4l2_config("/dev/video-arpipe-none");
  try {
    make_live_source(config);
    ADD_FAILURE() << "opened a device that does not exist";
  } catch (const CameraError& e) {
    EXPECT_EQ(e.kind(), CameraError::Kind::Missing);
    EXPECT_NE(std::string(e.what()).find("/dev/video-arpipe-none"), std::string::npos);
  }
}

// Start-of-exposure timestamps: every frame's pixels, sequence, exposure start (to the µs of a
// timeval), exposure and gains are the recording's exactly (exposures and gains are whole control
// units by construction). Real-time pacing: control events and buffers interleave as on a camera
// whose frames are dequeued as they come (see the note in v4l2_stream.cpp on a lagging reader).
TEST(V4L2Source, StreamsTheRecordingsPixelsTimestampsAndExposureExactly) {
  const auto dir = test::v4l2_scratch("exact");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 10);
  test::StandinDevice device(dir, recording, "pacing = \"realtime\"\ntimestamp_source = \"soe\"");
  auto config = v4l2_config();
  config.readout_ns = 5'000'000;
  auto source = make_live_source(config);
  const RecordingReader reader(recording);
  const auto frames = take_frames(*source, 10);
  ASSERT_EQ(frames.size(), 10u);
  for (size_t i = 0; i < frames.size(); ++i) {
    Frame truth;
    reader.read(i, truth);
    const auto& m = frames[i].meta;
    EXPECT_EQ(frames[i].data, truth.data) << "frame " << i;
    EXPECT_EQ(m.sequence, i);
    EXPECT_EQ(m.exposure_start_ns, to_microseconds(truth.meta.exposure_start_ns)) << "frame " << i;
    EXPECT_EQ(m.raw_timestamp_meaning, TimestampMeaning::StartOfExposure);
    EXPECT_EQ(m.exposure_ns, truth.meta.exposure_ns) << "frame " << i;
    EXPECT_DOUBLE_EQ(m.analogue_gain, truth.meta.analogue_gain) << "frame " << i;
    EXPECT_DOUBLE_EQ(m.digital_gain, truth.meta.digital_gain) << "frame " << i;
    EXPECT_EQ(m.readout_ns, 5'000'000);
  }
  // The exposure changed 6 times over these frames and each change came as an event, not a poll.
  EXPECT_GE(source->counters().stream.control_events, 6u);
  EXPECT_EQ(source->counters().stream.sequence_gaps, 0u);
}

// End-of-frame timestamps become the same exposure starts once exposure and readout are taken off.
TEST(V4L2Source, EndOfFrameTimestampsAreNormalisedToTheExposureStart) {
  const auto dir = test::v4l2_scratch("eof");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 6);
  test::StandinDevice device(dir, recording, "pacing = \"realtime\"\ntimestamp_source = \"eof\"");
  auto config = v4l2_config();
  config.readout_ns = 5'000'000;
  config.timestamp_offset_ns = -250'000;  // a per-camera correction is added after normalising
  auto source = make_live_source(config);
  const RecordingReader reader(recording);
  const auto frames = take_frames(*source, 6);
  ASSERT_EQ(frames.size(), 6u);
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& truth = reader.metadata(i);
    const auto& m = frames[i].meta;
    EXPECT_EQ(m.raw_timestamp_meaning, TimestampMeaning::EndOfFrame);
    EXPECT_EQ(m.raw_timestamp_ns, to_microseconds(truth.exposure_start_ns + truth.exposure_ns + truth.readout_ns));
    EXPECT_EQ(m.exposure_start_ns, to_microseconds(truth.exposure_start_ns) - 250'000) << "frame " << i;
  }
}

// Manual exposure and gain from the config: the camera is switched out of auto and reports them.
TEST(V4L2Source, ManualExposureAndGainFromTheConfig) {
  const auto dir = test::v4l2_scratch("manual");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 6);
  test::StandinDevice device(dir, recording, "pacing = \"fast\"");
  auto config = v4l2_config();
  config.exposure_us = 8000;
  config.gain = 2.5;
  auto source = make_live_source(config);
  const auto frames = take_frames(*source, 6);
  ASSERT_EQ(frames.size(), 6u);
  for (const auto& frame : frames) {
    EXPECT_EQ(frame.meta.exposure_ns, 8'000'000);
    EXPECT_DOUBLE_EQ(frame.meta.analogue_gain, 2.5);
  }
}

// MJPEG (what UVC webcams send at high rates) arrives decoded to RGB24. The stand-in encodes at
// quality 90 with 4:2:2 chroma, so the decoded frame differs from the recording's by the JPEG loss:
// a mean of at most 2 levels (measured 0.9 on the default capture).
TEST(V4L2Source, MjpegIsDecodedToRgb) {
  const auto dir = test::v4l2_scratch("mjpeg");
  test::StandinDevice device(dir, default_capture(), "formats = [\"MJPG\"]\npacing = \"fast\"\njpeg_quality = 90");
  auto config = v4l2_config();
  auto source = make_live_source(config);
  EXPECT_EQ(source->format().camera_format, "MJPG");
  EXPECT_EQ(source->format().format, PixelFormat::RGB24);
  const auto frames = take_frames(*source, 3);
  ASSERT_EQ(frames.size(), 3u);
  const RecordingReader reader(default_capture());
  for (size_t i = 0; i < frames.size(); ++i) {
    Frame truth;
    reader.read(i, truth);
    std::vector<uint8_t> rgb;
    to_rgb24(truth, rgb);
    ASSERT_EQ(frames[i].data.size(), rgb.size());
    double sum = 0;
    for (size_t b = 0; b < rgb.size(); ++b) sum += std::abs(int(frames[i].data[b]) - int(rgb[b]));
    EXPECT_LT(sum / double(rgb.size()), 2.0) << "frame " << i;
    EXPECT_EQ(frames[i].meta.exposure_start_ns, to_microseconds(truth.meta.exposure_start_ns));
  }
}

// Frames the driver skips show as sequence gaps: counted by the stream, and visible to the pipeline
// as a jump in the sequence numbers.
TEST(V4L2Source, SequenceGapsAreCountedAsDrops) {
  const auto dir = test::v4l2_scratch("drops");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 10);
  test::StandinDevice device(dir, recording, "pacing = \"fast\"\n[[device.fault]]\nframe = 4\nkind = \"drop\"\ncount = 3");
  auto source = make_live_source(v4l2_config());
  const auto frames = take_frames(*source, 7);
  ASSERT_EQ(frames.size(), 7u);
  const RecordingReader reader(recording);
  std::vector<uint64_t> sequences;
  for (const auto& f : frames) sequences.push_back(f.meta.sequence);
  EXPECT_EQ(sequences, (std::vector<uint64_t>{0, 1, 2, 3, 7, 8, 9}));
  EXPECT_EQ(frames[4].meta.exposure_start_ns, to_microseconds(reader.metadata(7).exposure_start_ns));  // 4..6 skipped
  EXPECT_EQ(source->counters().stream.sequence_gaps, 3u);
}

// Unplugged mid-stream and back 150 ms later: the source closes the device, retries with backoff
// and resumes, with the sequence still rising; nothing throws.
TEST(V4L2Source, SurvivesAnUnplugAndResumesWhenTheCameraReturns) {
  const auto dir = test::v4l2_scratch("unplug");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 10);
  test::StandinDevice device(
      dir, recording, "pacing = \"fast\"\n[[device.fault]]\nframe = 4\nkind = \"unplug\"\nreplug_after_ms = 150");
  auto source = make_live_source(v4l2_config());
  const auto frames = take_frames(*source, 5);
  ASSERT_EQ(frames.size(), 5u);
  const RecordingReader reader(recording);
  // Which recording frame each one is (by its exact exposure start). Frames done but not yet
  // dequeued when the camera vanished are lost, as on hardware; the sequence numbers after the
  // reconnect account for them exactly (estimated from the exposure times and the interval).
  std::vector<int64_t> index;
  for (const auto& f : frames) {
    int64_t found = -1;
    for (size_t i = 0; i < reader.frame_count(); ++i)
      if (to_microseconds(reader.metadata(i).exposure_start_ns) == f.meta.exposure_start_ns) found = int64_t(i);
    ASSERT_GE(found, 0) << "a frame that is not in the recording";
    index.push_back(found);
  }
  EXPECT_EQ(index.front(), 0);
  for (size_t i = 1; i < frames.size(); ++i) {
    EXPECT_GT(index[i], index[i - 1]);
    EXPECT_EQ(int64_t(frames[i].meta.sequence - frames[i - 1].meta.sequence), index[i] - index[i - 1]) << "frame " << i;
  }
  const auto c = source->counters();
  EXPECT_EQ(c.disconnects, 1u);
  EXPECT_EQ(c.reconnects, 1u);
  EXPECT_GE(c.failed_opens, 1u);  // the node was gone for 150 ms; the first retry is after 20 ms
  EXPECT_NE(source->health().find("connected"), std::string::npos);
}

// An I/O error from DQBUF is treated like a disappearance: closed, reopened, resumed.
TEST(V4L2Source, RecoversFromAnIoError) {
  const auto dir = test::v4l2_scratch("eio");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 8);
  test::StandinDevice device(dir, recording, "pacing = \"fast\"\n[[device.fault]]\nframe = 3\nkind = \"eio\"");
  auto source = make_live_source(v4l2_config());
  const auto frames = take_frames(*source, 6);
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_EQ(source->counters().disconnects, 1u);
  EXPECT_EQ(source->counters().reconnects, 1u);
}

// A stall longer than the frame timeout is counted and survived; frames then resume.
TEST(V4L2Source, CountsTimeoutsAndResumesAfterAStall) {
  const auto dir = test::v4l2_scratch("stall");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 6);
  test::StandinDevice device(dir, recording,
                             "pacing = \"fast\"\n[[device.fault]]\nframe = 2\nkind = \"stall\"\nduration_ms = 500");
  auto config = v4l2_config();
  config.frame_timeout_ms = 200;  // 500 ms of silence: two timeouts, below the three that reopen
  auto source = make_live_source(config);
  const auto frames = take_frames(*source, 6);
  ASSERT_EQ(frames.size(), 6u);
  const auto c = source->counters();
  EXPECT_EQ(c.stream.timeouts, 2u);
  EXPECT_EQ(c.disconnects, 0u);
}

// Spurious wake-ups (poll says ready, DQBUF says EAGAIN) and a buffer flagged corrupt are counted,
// not handed on, and the stream goes on.
TEST(V4L2Source, SurvivesAnEagainStormAndACorruptBuffer) {
  const auto dir = test::v4l2_scratch("eagain");
  const auto recording = test::write_auto_exposure_recording(dir / "rec", 8);
  test::StandinDevice device(dir, recording,
                             "pacing = \"fast\"\n[[device.fault]]\nframe = 2\nkind = \"eagain\"\ncount = 50\n"
                             "[[device.fault]]\nframe = 5\nkind = \"error_buffer\"");
  auto source = make_live_source(v4l2_config());
  const auto frames = take_frames(*source, 7);
  ASSERT_EQ(frames.size(), 7u);
  const auto c = source->counters();
  EXPECT_EQ(c.stream.again, 50u);
  EXPECT_EQ(c.stream.error_buffers, 1u);
  EXPECT_EQ(frames[5].meta.sequence, 6u);  // the corrupt frame 5 is a gap the pipeline will count
}

// A /dev/v4l/by-id style link opens the device it points at.
TEST(V4L2Source, OpensThroughAByIdLink) {
  const auto dir = test::v4l2_scratch("by-id");
  test::StandinDevice device(dir, default_capture(), "pacing = \"fast\"");
  const fs::path link = dir / "usb-arpipe_test_camera-video-index0";
  fs::create_symlink(kStandinDevice, link);
  auto source = make_live_source(v4l2_config(link.string()));
  EXPECT_NE(source->describe().find("usb-arpipe_test_camera"), std::string::npos);
  EXPECT_EQ(take_frames(*source, 2).size(), 2u);
}

// Real-time pacing: frames arrive on the recording's schedule, and their timestamps are its own.
TEST(V4L2Source, RealtimePacingDeliversOnTheRecordingsSchedule) {
  const auto dir = test::v4l2_scratch("realtime");
  test::StandinDevice device(dir, default_capture(), "pacing = \"realtime\"");
  // From before the stream starts (the source starts it): the sixth frame falls due 5 intervals of
  // 33.3 ms after STREAMON, so no scheduling can deliver it sooner than 166.7 ms after this.
  const auto start = std::chrono::steady_clock::now();
  auto source = make_live_source(v4l2_config());
  const auto frames = take_frames(*source, 6);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(frames.size(), 6u);
  EXPECT_GE(seconds, 5 * 0.033'333'333);
  EXPECT_LT(seconds, 2.0);  // slack for a loaded machine and the sanitizers' slower setup
  const RecordingReader reader(default_capture());
  for (size_t i = 0; i < frames.size(); ++i)
    EXPECT_EQ(frames[i].meta.exposure_start_ns, to_microseconds(reader.metadata(i).exposure_start_ns)) << "frame " << i;
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

// Counts frames and records the camera images' memory the sinks were handed.
class MemorySink final : public FrameSink {
 public:
  std::string describe() const override { return "test: memory"; }
  void consume(const FrameContext& ctx) noexcept override { addresses.push_back(ctx.camera.data.data()); }
  std::vector<const uint8_t*> addresses;
};

// issue 24's "zero allocations per frame in steady state": the camera images' memory goes from the
// sinks back to the source, which copies the driver's buffer into it. Through the daemon's own
// pipeline (no stages: the path from the driver to the sinks alone), every frame is one copy, and
// after the first frames in flight none allocates: the images reuse a handful of memory blocks.
TEST(V4L2Source, ThePipelineRecyclesFrameMemoryAndCopiesEachFrameOnce) {
  const auto dir = test::v4l2_scratch("recycle");
  test::StandinDevice device(dir, default_capture(), "formats = [\"YUYV\"]\npacing = \"fast\"\nloop = true");
  Config config;
  config.source = v4l2_config();
  config.pipeline.max_frames = 120;
  auto sink = std::make_unique<MemorySink>();
  MemorySink& memory = *sink;
  std::vector<std::unique_ptr<FrameSink>> sinks;
  sinks.push_back(std::move(sink));
  PipelineRunner runner(make_live_source(config.source), [] { return std::vector<std::unique_ptr<Stage>>{}; },
                        std::move(sinks), config);
  runner.start();
  runner.wait();
  const PipelineStatus status = runner.status();
  ASSERT_TRUE(status.capture.has_value());
  // A live camera's queues drop their oldest frame when processing or a sink falls behind (a slow
  // machine, the sanitizers): every frame reaches the sink or is a counted drop. A dropped frame's
  // memory goes back to the source like a consumed one's, so drops allocate nothing either.
  const uint64_t dropped = status.metrics.queue_drops;
  ASSERT_EQ(status.sinks.size(), 1u);
  EXPECT_EQ(memory.addresses.size() + dropped + status.sinks[0].dropped, 120u);  // the sink's queue drops too
  EXPECT_EQ(status.capture->frames, 120u);
  EXPECT_EQ(status.capture->copies, 120u);
  // Frames in flight at most: the queues to processing and to the sink thread (queue_depth each),
  // the sink's own queue, and one in each of the capture, processing, sink and sink-worker threads.
  const size_t in_flight = size_t(2 * config.pipeline.queue_depth + config.pipeline.sink_queue_depth) + 4;
  EXPECT_LE(status.capture->frame_allocations, in_flight) << dropped << " dropped by the processing queue";
  std::vector<const uint8_t*> distinct(memory.addresses);
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  EXPECT_LE(distinct.size(), size_t(status.capture->frame_allocations));  // every block was counted
}

}  // namespace
}  // namespace arpipe

namespace arpipe {
namespace {

// Three frames of the default capture as the source gets them from a stand-in serving `format`.
std::vector<Frame> frames_served_as(const std::string& name, const std::string& format, const std::string& buffer_type,
                                    CaptureFormat asked) {
  const auto dir = test::v4l2_scratch("layout-" + name);
  test::StandinDevice device(dir, default_capture(),
                             fmt::format("formats = [\"{}\"]\nbuffer_type = \"{}\"\npacing = \"fast\"", format, buffer_type));
  auto config = v4l2_config();
  config.pixel_format = asked;
  auto source = make_live_source(config);
  return take_frames(*source, 3);
}

// Issue 24's multi-planar capture and new formats, end to end through the stand-in (which makes
// each by reordering the YUYV or NV12 bytes of the recording's frame, tests/v4l2_standin/
// yuv_layouts.h): the source must give exactly the frame a camera sending YUYV or NV12 gives, with
// the same sequence and exposure times.
TEST(V4L2Source, MultiPlanarAndReorderedFormatsGiveTheFramesOfTheFormatTheyCarry) {
  const std::vector<Frame> yuyv = frames_served_as("yuyv", "YUYV", "single", CaptureFormat::YUYV);
  const std::vector<Frame> nv12 = frames_served_as("nv12", "NV12", "single", CaptureFormat::NV12);
  ASSERT_EQ(yuyv.size(), 3u);
  ASSERT_EQ(nv12.size(), 3u);
  struct Case {
    const char* served;
    const char* buffer_type;
    CaptureFormat asked;
    const std::vector<Frame>& expected;
  };
  const Case cases[] = {{"YUYV", "mplane", CaptureFormat::YUYV, yuyv},     {"UYVY", "single", CaptureFormat::UYVY, yuyv},
                        {"YVYU", "mplane", CaptureFormat::YVYU, yuyv},     {"NV16", "single", CaptureFormat::NV16, yuyv},
                        {"NV16M", "mplane", CaptureFormat::NV16M, yuyv},   {"NV12", "mplane", CaptureFormat::NV12, nv12},
                        {"NV21", "single", CaptureFormat::NV21, nv12},     {"YU12", "mplane", CaptureFormat::YUV420, nv12},
                        {"NV12M", "mplane", CaptureFormat::NV12M, nv12},   {"NV21M", "mplane", CaptureFormat::NV21M, nv12},
                        {"YUV420M", "mplane", CaptureFormat::YUV420M, nv12}};
  for (const Case& c : cases) {
    SCOPED_TRACE(fmt::format("{} ({})", c.served, c.buffer_type));
    const std::vector<Frame> got = frames_served_as(c.served, c.served, c.buffer_type, c.asked);
    ASSERT_EQ(got.size(), 3u);
    for (size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(got[i].format, c.expected[i].format);
      EXPECT_EQ(got[i].bytes_per_line, c.expected[i].bytes_per_line);
      EXPECT_TRUE(got[i].data == c.expected[i].data) << "frame " << i;
      EXPECT_EQ(got[i].meta.sequence, c.expected[i].meta.sequence);
      EXPECT_EQ(got[i].meta.exposure_start_ns, c.expected[i].meta.exposure_start_ns);
    }
  }
}

}  // namespace
}  // namespace arpipe
