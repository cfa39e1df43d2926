// PipelineRunner tests with a scripted fake source, fake stages and fake sinks: delivery and order,
// live-queue drops and sequence gaps counted exactly, stop/max_frames, reconfigure, health, metrics.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <pthread.h>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/pipeline/pipeline_runner.h"
#include "core/pipeline/sink_worker.h"
#include "core/system/thread_cpu.h"

namespace arpipe {
namespace {

// ---------------------------------------------------------------------------------------------
// Fakes. Each one writes what happened into a shared log that the test reads while the runner
// owns the fake itself. A log's condition variable lets the test wait for an event without timing.

struct SharedLog {
  std::mutex mutex;
  std::condition_variable changed;

  // Bounded: a frame that never comes (dropped upstream on a loaded machine) fails the test by
  // name instead of hanging it.
  template <typename Predicate>
  void wait_for(Predicate done) {
    std::unique_lock lock(mutex);
    if (!changed.wait_for(lock, std::chrono::seconds(120), [&] { return done(); }))
      ADD_FAILURE() << "waited 120 s for an event of the fakes that did not come";
  }
};

constexpr int kFrameWidth = 4, kFrameHeight = 2;

// A tiny RGB24 frame whose bytes all carry the low byte of its sequence number, so a sink can tell
// that it got the pixels that belong to the metadata.
Frame make_frame(uint64_t sequence) {
  Frame f = Frame::allocate(PixelFormat::RGB24, kFrameWidth, kFrameHeight);
  std::fill(f.data.begin(), f.data.end(), uint8_t(sequence & 0xff));
  f.meta.sequence = sequence;
  f.meta.exposure_start_ns = 1'000'000'000 + int64_t(sequence) * 33'000'000;
  f.meta.frame_duration_ns = 33'000'000;
  return f;
}

struct SourceAction {
  enum Kind { Frame, Retry, Throw } kind = Frame;
  uint64_t sequence = 0;
};
SourceAction frame_with(uint64_t sequence) { return {SourceAction::Frame, sequence}; }
constexpr SourceAction kRetry{SourceAction::Retry, 0};
constexpr SourceAction kThrow{SourceAction::Throw, 0};

// What the source does once its scripted actions are used up.
enum class AfterScript {
  EndOfStream,           // a recording that ended
  BlockUntilInterrupted, // a camera with no frame coming; returns Retry once interrupt() is called
  EndlessFrames,         // frames with increasing sequence numbers, as fast as they are taken
};

struct SourceLog : SharedLog {
  int next_calls = 0;
  bool end_reached = false;
  bool interrupted = false;
};

class FakeSource : public FrameSource {
 public:
  // before_next(n) runs at the start of the n-th call of next() (from 0), outside any lock: a
  // test uses it to hold the camera back until the pipeline reached a known state.
  FakeSource(std::vector<SourceAction> script, AfterScript after, bool live, std::shared_ptr<SourceLog> log,
             std::function<void(int)> before_next = {})
      : script_(std::move(script)), after_(after), live_(live), log_(std::move(log)),
        before_next_(std::move(before_next)) {}

  std::string describe() const override { return "fake source"; }
  bool is_live() const override { return live_; }
  std::shared_ptr<const CameraModel> camera_model() const override { return nullptr; }

  SourceStatus next(Frame& frame) override {
    if (before_next_) before_next_(calls_);
    ++calls_;
    std::unique_lock lock(log_->mutex);
    ++log_->next_calls;
    log_->changed.notify_all();
    if (position_ < script_.size()) {
      const SourceAction action = script_[position_++];
      switch (action.kind) {
        case SourceAction::Frame: frame = make_frame(action.sequence); return SourceStatus::Frame;
        case SourceAction::Retry: return SourceStatus::Retry;
        case SourceAction::Throw: throw std::runtime_error("the fake camera fell off the bus");
      }
    }
    switch (after_) {
      case AfterScript::EndOfStream:
        log_->end_reached = true;
        log_->changed.notify_all();
        return SourceStatus::EndOfStream;
      case AfterScript::BlockUntilInterrupted:
        log_->changed.wait(lock, [&] { return log_->interrupted; });
        return SourceStatus::Retry;
      case AfterScript::EndlessFrames: frame = make_frame(endless_sequence_++); return SourceStatus::Frame;
    }
    return SourceStatus::EndOfStream;
  }

  void interrupt() override {
    std::lock_guard lock(log_->mutex);
    log_->interrupted = true;
    log_->changed.notify_all();
  }

 private:
  std::vector<SourceAction> script_;
  size_t position_ = 0;
  AfterScript after_;
  bool live_;
  std::shared_ptr<SourceLog> log_;
  uint64_t endless_sequence_ = 0;
  std::function<void(int)> before_next_;
  int calls_ = 0;
};

struct StageLog : SharedLog {
  std::vector<std::string> configured;  // the source.camera of every configure() call, accepted or not
  std::vector<uint64_t> processed;      // sequence numbers
  std::vector<std::string> events;      // "look N" and "process N" in the order they happened
  bool inside_process = false;
};

// Configs are told apart by source.camera (a string), which no fake looks at otherwise.
Config config_marked(const std::string& marker, int queue_depth = 4, int64_t max_frames = 0) {
  Config config;
  config.source.camera = marker;
  config.pipeline.queue_depth = queue_depth;
  config.pipeline.max_frames = max_frames;
  return config;
}

struct StageBehaviour {
  std::string name = "fake";
  std::string refuse_marker;              // configure() throws for a config with this marker
  bool refuse_first_configure = false;
  double ms = 0.25;                       // the timing it records; exact in binary, so sums are exact
  bool skip_odd_sequences = false;        // records a skip reason on odd sequence numbers
  int latency = 0;                        // Stage::latency_frames
  std::function<void(const FrameContext&)> while_processing;  // delays or blocks, as a test needs

  static StageBehaviour named(std::string name) {
    StageBehaviour b;
    b.name = std::move(name);
    return b;
  }
  StageBehaviour refusing(std::string marker) const {
    auto b = *this;
    b.refuse_marker = std::move(marker);
    return b;
  }
  StageBehaviour refusing_first_configure() const {
    auto b = *this;
    b.refuse_first_configure = true;
    return b;
  }
  StageBehaviour timing(double stage_ms) const {
    auto b = *this;
    b.ms = stage_ms;
    return b;
  }
  StageBehaviour holding_back(int frames) const {
    auto b = *this;
    b.latency = frames;
    return b;
  }
  StageBehaviour skipping_odd_sequences() const {
    auto b = *this;
    b.skip_odd_sequences = true;
    return b;
  }
  StageBehaviour doing(std::function<void(const FrameContext&)> hook) const {
    auto b = *this;
    b.while_processing = std::move(hook);
    return b;
  }
};

class FakeStage : public Stage {
 public:
  FakeStage(StageBehaviour behaviour, std::shared_ptr<StageLog> log)
      : behaviour_(std::move(behaviour)), log_(std::move(log)) {}

  std::string_view name() const override { return behaviour_.name; }

  void configure(const Config& config) override {
    bool refuse = false;
    {
      std::lock_guard lock(log_->mutex);
      refuse = (behaviour_.refuse_first_configure && log_->configured.empty()) ||
               (!behaviour_.refuse_marker.empty() && config.source.camera == behaviour_.refuse_marker);
      log_->configured.push_back(config.source.camera);
      log_->changed.notify_all();
    }
    if (refuse)
      throw ConfigError(fmt::format("{} refuses source.camera '{}'", behaviour_.name, config.source.camera));
  }

  void process(FrameContext& ctx) noexcept override {
    {
      std::lock_guard lock(log_->mutex);
      log_->inside_process = true;
      log_->changed.notify_all();
    }
    if (behaviour_.while_processing) behaviour_.while_processing(ctx);
    const bool skip = behaviour_.skip_odd_sequences && ctx.camera.meta.sequence % 2 == 1;
    ctx.record_timing(behaviour_.name, behaviour_.ms, skip ? "odd frame" : "");
    std::lock_guard lock(log_->mutex);
    log_->processed.push_back(ctx.camera.meta.sequence);
    log_->events.push_back(fmt::format("process {}", ctx.camera.meta.sequence));
    log_->inside_process = false;
    log_->changed.notify_all();
  }

  int latency_frames() const noexcept override { return behaviour_.latency; }
  void look_ahead(const FrameContext& next) noexcept override {
    std::lock_guard lock(log_->mutex);
    log_->events.push_back(fmt::format("look {}", next.camera.meta.sequence));
  }

 private:
  StageBehaviour behaviour_;
  std::shared_ptr<StageLog> log_;
};

struct SinkLog : SharedLog {
  std::vector<uint64_t> sequences;
  std::vector<uint64_t> input_indices;
  std::vector<uint64_t> dropped_before;
  std::vector<std::vector<std::string>> stage_order;  // per frame, the stages' timings in order
  int pixel_mismatches = 0;
  int flushes = 0;
  int frames_after_flush = 0;
  std::vector<std::string> threads_at_first_frame;  // the process's thread names (top -H, /proc)
  std::string own_thread_name;                     // the thread consume() ran on
};

class FakeSink : public FrameSink {
 public:
  FakeSink(std::shared_ptr<SinkLog> log, std::chrono::microseconds delay = {}) : log_(std::move(log)), delay_(delay) {}
  std::string describe() const override { return "fake sink"; }

  void consume(const FrameContext& ctx) noexcept override {
    if (delay_.count() > 0) std::this_thread::sleep_for(delay_);  // a slow disk
    std::lock_guard lock(log_->mutex);
    log_->sequences.push_back(ctx.camera.meta.sequence);
    log_->input_indices.push_back(ctx.input_index);
    log_->dropped_before.push_back(ctx.dropped_before);
    std::vector<std::string> order;
    for (const auto& t : ctx.timings) order.push_back(t.stage);
    log_->stage_order.push_back(order);
    for (uint8_t b : ctx.camera.data)
      if (b != uint8_t(ctx.camera.meta.sequence & 0xff)) {
        ++log_->pixel_mismatches;
        break;
      }
    if (log_->flushes > 0) ++log_->frames_after_flush;
    if (log_->threads_at_first_frame.empty()) {
      for (const ThreadCpu& thread : threads_cpu()) log_->threads_at_first_frame.push_back(thread.name);
      char name[16] = {};
      pthread_getname_np(pthread_self(), name, sizeof name);
      log_->own_thread_name = name;
    }
    log_->changed.notify_all();
  }

  void flush() noexcept override {
    std::lock_guard lock(log_->mutex);
    ++log_->flushes;
    log_->changed.notify_all();
  }

 private:
  std::shared_ptr<SinkLog> log_;
  std::chrono::microseconds delay_;
};

// What a test's pipeline is made of; each call changes one thing from the default.
struct Setup {
  std::vector<SourceAction> script;
  AfterScript after = AfterScript::EndOfStream;
  bool live = false;
  std::vector<StageBehaviour> stages{StageBehaviour{}};
  std::vector<std::chrono::microseconds> sink_delays{std::chrono::microseconds(0)};
  Config config = config_marked("run");
  std::shared_ptr<SourceLog> source_log = std::make_shared<SourceLog>();  // made early so a stage can watch it
  std::function<void(int)> before_next;

  static Setup replaying(std::vector<SourceAction> script, AfterScript after = AfterScript::EndOfStream) {
    Setup s;
    s.script = std::move(script);
    s.after = after;
    return s;
  }
  static Setup endless() { return replaying({}, AfterScript::EndlessFrames); }
  Setup as_live_camera() && {
    live = true;
    return std::move(*this);
  }
  Setup with_stages(std::vector<StageBehaviour> list) && {
    stages = std::move(list);
    return std::move(*this);
  }
  Setup with_sink_delays(std::vector<std::chrono::microseconds> delays) && {
    sink_delays = std::move(delays);
    return std::move(*this);
  }
  Setup with_config(Config c) && {
    config = std::move(c);
    return std::move(*this);
  }
  Setup watched_by(std::shared_ptr<SourceLog> log) && {
    source_log = std::move(log);
    return std::move(*this);
  }
  Setup pausing_source_with(std::function<void(int)> hook) && {
    before_next = std::move(hook);
    return std::move(*this);
  }
};

// Builds a runner from fakes and keeps their logs.
struct Harness {
  std::shared_ptr<SourceLog> source_log;
  std::vector<std::shared_ptr<StageLog>> stage_logs;
  std::vector<std::shared_ptr<SinkLog>> sink_logs;
  std::unique_ptr<PipelineRunner> runner;

  explicit Harness(Setup setup) : source_log(setup.source_log) {
    for (size_t i = 0; i < setup.stages.size(); ++i) stage_logs.push_back(std::make_shared<StageLog>());
    std::vector<std::unique_ptr<FrameSink>> sinks;
    for (auto delay : setup.sink_delays) {
      sink_logs.push_back(std::make_shared<SinkLog>());
      sinks.push_back(std::make_unique<FakeSink>(sink_logs.back(), delay));
    }
    StageFactory factory = [stages = setup.stages, logs = stage_logs] {
      std::vector<std::unique_ptr<Stage>> made;
      for (size_t i = 0; i < stages.size(); ++i) made.push_back(std::make_unique<FakeStage>(stages[i], logs[i]));
      return made;
    };
    runner = std::make_unique<PipelineRunner>(
        std::make_unique<FakeSource>(std::move(setup.script), setup.after, setup.live, source_log,
                                     std::move(setup.before_next)),
        factory,
        std::move(sinks), setup.config);
  }

  void wait_until_sink_has(size_t sink, size_t frames) {
    sink_logs[sink]->wait_for([&] { return sink_logs[sink]->sequences.size() >= frames; });
  }
  std::vector<std::string> configured(size_t stage) {
    std::lock_guard lock(stage_logs[stage]->mutex);
    return stage_logs[stage]->configured;
  }
};

std::vector<SourceAction> frames_0_to(uint64_t count) {
  std::vector<SourceAction> script;
  for (uint64_t s = 0; s < count; ++s) script.push_back(frame_with(s));
  return script;
}

std::vector<uint64_t> iota(uint64_t count) {
  std::vector<uint64_t> v;
  for (uint64_t s = 0; s < count; ++s) v.push_back(s);
  return v;
}

// ---------------------------------------------------------------------------------------------

TEST(PipelineRunner, ReplayDeliversEveryFrameToEverySinkOnceAndInOrder) {
  constexpr uint64_t kFrames = 60;
  // queue_depth 1 and a slow sink: the source must wait (Block), never drop.
  Harness h(Setup::replaying(frames_0_to(kFrames))
                .with_stages({StageBehaviour::named("first").timing(0.25).skipping_odd_sequences(),
                              StageBehaviour::named("second").timing(1.5)})
                .with_sink_delays({std::chrono::microseconds(300), std::chrono::microseconds(0)})
                .with_config(config_marked("run", 1)));
  h.runner->start();
  h.runner->wait();
  EXPECT_TRUE(h.runner->finished());

  for (const auto& log : h.sink_logs) {
    EXPECT_EQ(log->sequences, iota(kFrames));
    EXPECT_EQ(log->input_indices, iota(kFrames));
    EXPECT_EQ(log->dropped_before, std::vector<uint64_t>(kFrames, 0));
    EXPECT_EQ(log->pixel_mismatches, 0);
    EXPECT_EQ(log->flushes, 1);
    EXPECT_EQ(log->frames_after_flush, 0);
    for (const auto& order : log->stage_order) EXPECT_EQ(order, (std::vector<std::string>{"first", "second"}));
  }
  for (const auto& log : h.stage_logs) EXPECT_EQ(log->processed, iota(kFrames));

  const PipelineMetrics m = h.runner->metrics();
  EXPECT_EQ(m.frames_in, kFrames);
  EXPECT_EQ(m.frames_out, kFrames);
  EXPECT_EQ(m.queue_drops, 0u);
  EXPECT_EQ(m.sequence_gaps, 0u);
  EXPECT_EQ(m.source_retries, 0u);
  // Stage timings summed per stage: 0.25 and 1.5 are exact binary fractions, so the sums are exact.
  ASSERT_EQ(m.stages.size(), 2u);
  EXPECT_EQ(m.stages.at("first").runs, kFrames);
  EXPECT_EQ(m.stages.at("first").total_ms, 0.25 * kFrames);
  EXPECT_EQ(m.stages.at("first").skips, (std::map<std::string, uint64_t>{{"odd frame", kFrames / 2}}));
  EXPECT_EQ(m.stages.at("second").runs, kFrames);
  EXPECT_EQ(m.stages.at("second").total_ms, 1.5 * kFrames);
  EXPECT_TRUE(m.stages.at("second").skips.empty());
}

// Each of the pipeline's threads carries its part's name, so that top -H and the pipeline
// benchmark's CPU table (bench/pipeline_run.h) tell them apart.
TEST(PipelineRunner, ItsThreadsAreNamedForTheirParts) {
  // A slow sink and queues one deep: every thread is still at work (or blocked) at the first frame.
  Harness h(Setup::replaying(frames_0_to(30))
                .with_sink_delays({std::chrono::milliseconds(5)})
                .with_config(config_marked("run", 1)));
  h.runner->start();
  h.runner->wait();
  const SinkLog& log = *h.sink_logs.at(0);
  for (const char* name : {"arp-capture", "arp-process", "arp-sinks"})
    EXPECT_NE(std::find(log.threads_at_first_frame.begin(), log.threads_at_first_frame.end(), name),
              log.threads_at_first_frame.end())
        << name;
  EXPECT_TRUE(log.own_thread_name.starts_with("arp-sink ")) << log.own_thread_name;
  // A keyed sink's thread takes the key's short name.
  auto keyed_log = std::make_shared<SinkLog>();
  {
    SinkWorker worker("sinks.results", std::make_unique<FakeSink>(keyed_log), 2, OverflowPolicy::Block);
    worker.start();
    worker.push(std::make_shared<const FrameContext>());
  }  // finished: the frame was consumed
  EXPECT_EQ(keyed_log->own_thread_name, "arp-sink result");  // "arp-sink results", cut to 15 bytes
}

TEST(PipelineRunner, StageThatHoldsFramesBackSeesTheNextFrameFirstAndNothingIsLost) {
  // The motion stage with motion.latency_frames = 1: each frame waits, after the stages before it,
  // until the next one has been through them and shown to the stage; the last goes on at the end.
  constexpr uint64_t kFrames = 10;
  Harness h(Setup::replaying(frames_0_to(kFrames))
                .with_stages({StageBehaviour::named("before"), StageBehaviour::named("held").holding_back(1),
                              StageBehaviour::named("after")}));
  h.runner->start();
  h.runner->wait();
  const auto& sink = *h.sink_logs[0];
  EXPECT_EQ(sink.sequences, iota(kFrames));
  EXPECT_EQ(sink.flushes, 1);
  EXPECT_EQ(sink.frames_after_flush, 0);
  for (const auto& order : sink.stage_order) EXPECT_EQ(order, (std::vector<std::string>{"before", "held", "after"}));
  std::vector<std::string> expected{"look 0"};
  for (uint64_t s = 1; s < kFrames; ++s) {
    expected.push_back(fmt::format("look {}", s));
    expected.push_back(fmt::format("process {}", s - 1));
  }
  expected.push_back(fmt::format("process {}", kFrames - 1));
  EXPECT_EQ(h.stage_logs[1]->events, expected);
  for (const auto& log : h.stage_logs) EXPECT_EQ(log->processed, iota(kFrames));
  EXPECT_EQ(h.runner->metrics().frames_out, kFrames);
}

TEST(PipelineRunner, LiveSourceDropsOldestWhenProcessingFallsBehindAndCountsExactly) {
  constexpr uint64_t kFrames = 40;
  // The camera holds frame 1 back until the stage has taken frame 0, and the stage is stuck on
  // frame 0 until the camera has delivered everything. With queue_depth 1, frames 1..38 must be
  // dropped and the newest, 39, must be waiting: no scheduling can change these counts.
  auto source_log = std::make_shared<SourceLog>();
  auto gate = std::make_shared<SharedLog>();
  auto frame_0_taken = std::make_shared<bool>(false);
  const auto stuck_on_frame_0 = StageBehaviour::named("slow").doing([=](const FrameContext& ctx) {
    if (ctx.camera.meta.sequence != 0) return;
    {
      std::lock_guard lock(gate->mutex);
      *frame_0_taken = true;
      gate->changed.notify_all();
    }
    source_log->wait_for([&] { return source_log->end_reached; });
  });
  Harness h(Setup::replaying(frames_0_to(kFrames))
                .as_live_camera()
                .with_stages({stuck_on_frame_0})
                .with_config(config_marked("run", 1))
                .watched_by(source_log)
                .pausing_source_with([=](int call) {
                  if (call == 1) gate->wait_for([&] { return *frame_0_taken; });
                }));
  h.runner->start();
  h.runner->wait();

  const PipelineMetrics m = h.runner->metrics();
  EXPECT_EQ(m.frames_in, kFrames);
  EXPECT_EQ(m.frames_out, 2u);
  EXPECT_EQ(m.queue_drops, kFrames - 2);
  EXPECT_EQ(m.frames_in, m.frames_out + m.queue_drops);
  EXPECT_EQ(m.sequence_gaps, 0u);

  const auto& sink = *h.sink_logs[0];
  EXPECT_EQ(sink.sequences, (std::vector<uint64_t>{0, kFrames - 1}));  // the newest frame is never dropped
  EXPECT_EQ(sink.input_indices, (std::vector<uint64_t>{0, kFrames - 1}));
  // Queue drops are losses just like sequence gaps (FrameContext::dropped_before): the frame after
  // them says how many frames were lost just before it.
  EXPECT_EQ(sink.dropped_before, (std::vector<uint64_t>{0, kFrames - 2}));
  EXPECT_EQ(sink.flushes, 1);
}

TEST(PipelineRunner, SequenceGapsAreCountedAndReportedOnTheFrameAfterThem) {
  Harness h(Setup::replaying(
      {frame_with(7), frame_with(8), frame_with(9), frame_with(12), frame_with(13), frame_with(20)}));
  h.runner->start();
  h.runner->wait();
  const PipelineMetrics m = h.runner->metrics();
  EXPECT_EQ(m.sequence_gaps, 2u + 6u);  // 10, 11 and 14..19 never came
  EXPECT_EQ(m.frames_in, 6u);
  EXPECT_EQ(m.frames_out, 6u);
  EXPECT_EQ(h.sink_logs[0]->sequences, (std::vector<uint64_t>{7, 8, 9, 12, 13, 20}));
  EXPECT_EQ(h.sink_logs[0]->dropped_before, (std::vector<uint64_t>{0, 0, 0, 2, 0, 6}));
  EXPECT_EQ(h.sink_logs[0]->input_indices, iota(6));
}

TEST(PipelineRunner, MaxFramesStopsAfterThatManyFrames) {
  Harness h(Setup::endless().with_config(config_marked("run", 2, 7)));
  h.runner->start();
  h.runner->wait();
  EXPECT_TRUE(h.runner->finished());
  EXPECT_EQ(h.sink_logs[0]->sequences, iota(7));
  EXPECT_EQ(h.source_log->next_calls, 7);  // not asked for an eighth frame
  EXPECT_EQ(h.runner->metrics().frames_out, 7u);
  EXPECT_EQ(h.sink_logs[0]->flushes, 1);
}

TEST(PipelineRunner, StopWhileTheSourceBlocksInterruptsItDrainsAndFlushes) {
  Harness h(Setup::replaying(frames_0_to(3), AfterScript::BlockUntilInterrupted)
                .with_sink_delays({std::chrono::microseconds(0), std::chrono::microseconds(0)}));
  h.runner->start();
  h.wait_until_sink_has(0, 3);
  h.wait_until_sink_has(1, 3);
  // The fourth call of next() is the one that blocks; stop only once it has begun, or the capture
  // thread may see the stop request first and never call it.
  h.source_log->wait_for([&] { return h.source_log->next_calls >= 4; });
  EXPECT_FALSE(h.runner->finished());
  h.runner->stop();
  h.runner->wait();  // returns only if stop() reached the blocked next()
  EXPECT_TRUE(h.source_log->interrupted);
  EXPECT_TRUE(h.runner->finished());
  for (const auto& log : h.sink_logs) {
    EXPECT_EQ(log->sequences, iota(3));
    EXPECT_EQ(log->flushes, 1);
  }
  EXPECT_EQ(h.runner->metrics().source_retries, 1u);  // the interrupted next() said Retry
}

TEST(PipelineRunner, StopDrainsWhatIsQueuedThroughEveryStageAndSink) {
  Harness h(Setup::endless()
                .with_stages({StageBehaviour::named("a"), StageBehaviour::named("b")})
                .with_sink_delays({std::chrono::microseconds(200)})
                .with_config(config_marked("run", 3)));
  h.runner->start();
  h.wait_until_sink_has(0, 5);
  h.runner->stop();
  h.runner->wait();
  const PipelineMetrics m = h.runner->metrics();
  // Nothing a replay source handed over is lost on stop: every frame taken reached the sink.
  EXPECT_EQ(m.frames_in, m.frames_out);
  EXPECT_EQ(h.sink_logs[0]->sequences, iota(m.frames_out));
  EXPECT_EQ(h.stage_logs[0]->processed, iota(m.frames_out));
  EXPECT_EQ(h.stage_logs[1]->processed, iota(m.frames_out));
  EXPECT_EQ(h.sink_logs[0]->flushes, 1);
}

TEST(PipelineRunner, StageThatRefusesItsFirstConfigMakesStartThrowAndNothingRuns) {
  Harness h(Setup::replaying(frames_0_to(5))
                .with_stages({StageBehaviour::named("fine"), StageBehaviour::named("picky").refusing_first_configure(),
                              StageBehaviour::named("never")}));
  try {
    h.runner->start();
    ADD_FAILURE() << "start() did not throw";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("picky refuses source.camera 'run'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(h.source_log->next_calls, 0);
  EXPECT_TRUE(h.sink_logs[0]->sequences.empty());
  EXPECT_EQ(h.sink_logs[0]->flushes, 0);
  EXPECT_TRUE(h.configured(2).empty());  // configuring stopped at the first refusal
  for (const auto& log : h.stage_logs) EXPECT_TRUE(log->processed.empty());
  EXPECT_EQ(h.runner->metrics().frames_in, 0u);
  EXPECT_FALSE(h.runner->finished());
  h.runner.reset();  // the destructor copes with a runner that never started
}

TEST(PipelineRunner, StageFactoryThatThrowsMakesStartThrow) {
  auto source_log = std::make_shared<SourceLog>();
  PipelineRunner runner(
      std::make_unique<FakeSource>(frames_0_to(3), AfterScript::EndOfStream, false, source_log),
      []() -> std::vector<std::unique_ptr<Stage>> { throw std::runtime_error("no EGL display"); }, {},
      config_marked("run"));
  EXPECT_THROW(runner.start(), std::runtime_error);
  EXPECT_EQ(source_log->next_calls, 0);
}

TEST(PipelineRunner, ReconfigureRefusedByOneStagePutsEveryStageBackOnTheRunningConfig) {
  Harness h(Setup::endless()
                .with_stages({StageBehaviour::named("a"), StageBehaviour::named("b").refusing("refused"),
                              StageBehaviour::named("c")})
                .with_config(config_marked("original", 2)));
  h.runner->start();
  h.wait_until_sink_has(0, 1);

  std::string error = "stale text";
  EXPECT_FALSE(h.runner->reconfigure(config_marked("refused", 2), error));
  EXPECT_NE(error.find("stage b"), std::string::npos) << error;
  EXPECT_NE(error.find("b refuses source.camera 'refused'"), std::string::npos) << error;
  // a took the new config before b refused it, so it must have been given the old one again;
  // c never saw it, and ends on the old one too.
  EXPECT_EQ(h.configured(0), (std::vector<std::string>{"original", "refused", "original"}));
  EXPECT_EQ(h.configured(1), (std::vector<std::string>{"original", "refused", "original"}));
  EXPECT_EQ(h.configured(2).back(), "original");
  for (const auto& marker : h.configured(2)) EXPECT_NE(marker, "refused");

  EXPECT_TRUE(h.runner->reconfigure(config_marked("accepted", 2), error));
  EXPECT_EQ(error, "");
  for (size_t s = 0; s < 3; ++s) EXPECT_EQ(h.configured(s).back(), "accepted") << "stage " << s;

  // The accepted config is now the running one: a later refusal returns to it, not to the original.
  EXPECT_FALSE(h.runner->reconfigure(config_marked("refused", 2), error));
  for (size_t s = 0; s < 3; ++s) EXPECT_EQ(h.configured(s).back(), "accepted") << "stage " << s;

  h.runner->stop();
  h.runner->wait();
  EXPECT_EQ(h.runner->metrics().frames_in, h.runner->metrics().frames_out);
}

TEST(PipelineRunner, SourceRetriesAreCounted) {
  Harness h(Setup::replaying({frame_with(0), kRetry, kRetry, frame_with(1), kRetry, frame_with(2)}));
  h.runner->start();
  h.runner->wait();
  const PipelineMetrics m = h.runner->metrics();
  EXPECT_EQ(m.source_retries, 3u);
  EXPECT_EQ(m.frames_in, 3u);
  EXPECT_EQ(m.sequence_gaps, 0u);  // a retry is not a lost frame
  EXPECT_EQ(h.sink_logs[0]->sequences, iota(3));
}

TEST(PipelineRunner, SourceThatThrowsDoesNotKillThePipeline) {
  Harness h(Setup::replaying({frame_with(0), kThrow, frame_with(1), kThrow, kThrow, frame_with(2)}));
  h.runner->start();
  h.runner->wait();
  EXPECT_TRUE(h.runner->finished());
  EXPECT_EQ(h.sink_logs[0]->sequences, iota(3));
  EXPECT_EQ(h.sink_logs[0]->flushes, 1);
  EXPECT_EQ(h.source_log->next_calls, 7);  // kept asking after each throw, then got EndOfStream
}

TEST(PipelineRunner, UnhealthyWhileAStageIsStuckHealthyWhenIdle) {
  auto release = std::make_shared<SharedLog>();
  auto released = std::make_shared<bool>(false);
  const auto stuck = StageBehaviour::named("stuck").doing(
      [release, released](const FrameContext&) { release->wait_for([&] { return *released; }); });
  Harness h(Setup::replaying(frames_0_to(1), AfterScript::BlockUntilInterrupted).with_stages({stuck}));
  EXPECT_TRUE(h.runner->healthy(1));  // not started: nothing is stuck
  h.runner->start();
  h.stage_logs[0]->wait_for([&] { return h.stage_logs[0]->inside_process; });

  // At least 20 ms pass inside process() (sleep_for never returns early), so a 10 ms threshold is
  // exceeded however the threads are scheduled.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(h.runner->healthy(10'000'000));

  {
    std::lock_guard lock(release->mutex);
    *released = true;
    release->changed.notify_all();
  }
  h.wait_until_sink_has(0, 1);
  // The sink's own thread has left consume(), and the thread that hands frames to the sinks has
  // counted the frame out, which it does only once it is no longer busy with it (a sink may
  // consume the frame before that thread has finished handing it over).
  while (h.runner->status().sinks[0].consumed < 1 || h.runner->metrics().frames_out < 1)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  // Every thread now waits for a frame the source does not have: idle is healthy, even with a
  // threshold of 1 ns.
  EXPECT_TRUE(h.runner->healthy(1));

  h.runner->stop();
  h.runner->wait();
  EXPECT_TRUE(h.runner->healthy(1));
}

// A sink stuck on a hung disk must stop the watchdog too, not only a stuck stage.
// Each sink has its own queue: with a live camera a slow sink loses its own oldest frames (counted
// per sink) while a fast one takes every frame; nothing waits for the slow one.
TEST(PipelineRunner, LiveCameraASlowSinkDropsItsOwnFramesAndNeverTheOthers) {
  constexpr uint64_t kFrames = 150;
  // The camera delivers a frame every millisecond: slower than the stages, far faster than the
  // slow sink's 20 ms. Each sink's queue holds 32 frames: the fast sink stays far from that even on a
  // loaded machine (with 4, a fast sink's thread not scheduled for 4 ms dropped too: that is the
  // policy working, not a slow sink's harm), the slow one, taking about 8 frames in the run, overflows it.
  Config config = config_marked("run");
  config.pipeline.sink_queue_depth = 32;
  Harness h(Setup::replaying(frames_0_to(kFrames), AfterScript::BlockUntilInterrupted)
                .as_live_camera()
                .with_config(config)
                .pausing_source_with([](int) { std::this_thread::sleep_for(std::chrono::milliseconds(1)); })
                .with_sink_delays({std::chrono::microseconds(0), std::chrono::microseconds(20'000)}));
  h.runner->start();
  // Every frame is either handed to the sinks or (on a loaded machine, where the stages can fall
  // behind a 1 ms camera) dropped before them and counted; the fast sink then has every one handed over.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  const auto all_accounted = [&] {
    const PipelineMetrics m = h.runner->metrics();
    return m.frames_in == kFrames && m.frames_out + m.queue_drops == kFrames;
  };
  while (!all_accounted() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(all_accounted());
  const uint64_t handed_over = h.runner->metrics().frames_out;
  h.wait_until_sink_has(0, handed_over);
  h.runner->stop();
  h.runner->wait();
  const PipelineStatus status = h.runner->status();
  ASSERT_EQ(status.sinks.size(), 2u);
  EXPECT_EQ(status.sinks[0].dropped, 0u);
  EXPECT_EQ(status.sinks[0].consumed, handed_over);
  {
    std::lock_guard lock(h.sink_logs[0]->mutex);
    EXPECT_EQ(h.sink_logs[0]->sequences.size(), handed_over);
    EXPECT_TRUE(std::is_sorted(h.sink_logs[0]->sequences.begin(), h.sink_logs[0]->sequences.end()));
    EXPECT_EQ(h.sink_logs[0]->sequences.back(), kFrames - 1);
  }
  // The slow sink: fewer frames, the rest dropped and counted, in order, none twice.
  EXPECT_GT(status.sinks[1].dropped, 0u);
  EXPECT_EQ(status.sinks[1].consumed + status.sinks[1].dropped, handed_over);
  std::lock_guard lock(h.sink_logs[1]->mutex);
  EXPECT_EQ(h.sink_logs[1]->sequences.size(), status.sinks[1].consumed);
  EXPECT_TRUE(std::adjacent_find(h.sink_logs[1]->sequences.begin(), h.sink_logs[1]->sequences.end(),
                                 [](uint64_t a, uint64_t b) { return b <= a; }) == h.sink_logs[1]->sequences.end());
  EXPECT_EQ(h.sink_logs[1]->sequences.back(), kFrames - 1);  // the newest frame is never the one dropped
  EXPECT_EQ(h.sink_logs[1]->flushes, 1);
}

// A replay loses nothing: a slow sink makes the pipeline wait, and every sink gets every frame.
TEST(PipelineRunner, ReplayASlowSinkGetsEveryFrame) {
  Harness h(Setup::replaying(frames_0_to(40)).with_sink_delays({std::chrono::microseconds(0), std::chrono::microseconds(3'000)}));
  h.runner->start();
  h.runner->wait();
  for (size_t sink = 0; sink < 2; ++sink) {
    std::lock_guard lock(h.sink_logs[sink]->mutex);
    EXPECT_EQ(h.sink_logs[sink]->sequences, iota(40)) << "sink " << sink;
  }
  for (const SinkStats& stats : h.runner->status().sinks) EXPECT_EQ(stats.dropped, 0u);
  EXPECT_EQ(h.runner->metrics().latency_seconds.count(), 40u);
}

TEST(PipelineRunner, UnhealthyWhileASinkIsStuck) {
  Harness h(Setup::replaying(frames_0_to(1), AfterScript::BlockUntilInterrupted)
                .with_sink_delays({std::chrono::microseconds(1'000'000)}));
  h.runner->start();
  // The sink sits in consume() for a whole second (sleep_for never returns early), so a 10 ms
  // threshold is crossed while the test watches, however the threads are scheduled.
  bool seen_unhealthy = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(900);
  while (!seen_unhealthy && std::chrono::steady_clock::now() < deadline) {
    seen_unhealthy = !h.runner->healthy(10'000'000);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_TRUE(seen_unhealthy);
  h.wait_until_sink_has(0, 1);
  // The sink's own thread has left consume() (frames_out counts frames handed to the sinks).
  while (h.runner->status().sinks[0].consumed < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_TRUE(h.runner->healthy(1));
  h.runner->stop();
  h.runner->wait();
}

}  // namespace
}  // namespace arpipe
