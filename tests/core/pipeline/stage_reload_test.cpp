// Reloads through the PipelineRunner with stages whose assets load slowly (StageReloader): the
// loading runs on the reloading thread while frames flow, a refused or superseded reload is never
// applied later, a refusal puts the stages back without loading again; sinks are made last. A
// reload replaces the sinks whose part of the config changed at a frame boundary and adds or
// removes the stages that run only while the config asks for them.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/pipeline/optional_stage.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe {
namespace {

using namespace std::chrono_literals;

// Configs are told apart by source.camera (a string), which nothing here looks at otherwise.
Config marked(const std::string& marker) {
  Config config;
  config.source.camera = marker;
  config.pipeline.queue_depth = 2;
  return config;
}

// A latch the test opens; waiting threads see it open and everything written before opening.
struct Gate {
  std::mutex mutex;
  std::condition_variable changed;
  bool open = false;
  void release() {
    std::lock_guard lock(mutex);
    open = true;
    changed.notify_all();
  }
  void wait() {
    std::unique_lock lock(mutex);
    changed.wait(lock, [&] { return open; });
  }
};

// What the fakes saw, under one mutex, with a condition variable for the test to wait on.
struct Log {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::string> loaded;                                   // marker of every loader call
  std::vector<std::thread::id> loader_threads;
  std::vector<std::pair<std::string, std::string>> configured;       // (config marker, assets marker)
  std::thread::id processing_thread;
  size_t frames_processed = 0;
  size_t frames_consumed = 0;
  int sinks_made = 0;
  std::vector<std::string> sink_events;                              // "started", "frame", "flush"
  std::map<std::string, size_t> processed_by;                         // frames per stage name
  std::map<std::string, int> stages_made;                             // per stage name
  std::vector<std::string> slot_events;                               // "<tag> started|flush|closed"
  std::map<std::string, size_t> consumed_by;                          // frames per slot sink tag

  template <typename Predicate>
  bool wait_for(Predicate done, std::chrono::seconds timeout = 30s) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return done(); });
  }
  template <typename Change>
  void record(Change change) {
    std::lock_guard lock(mutex);
    change();
    changed.notify_all();
  }
};

// Frames as fast as they are taken, while `flowing`; otherwise next() waits (a camera with no
// frame coming) until frames flow again or interrupt().
struct Tap {
  std::mutex mutex;
  std::condition_variable changed;
  bool flowing = true;
  bool interrupted = false;
  void set(bool on) {
    std::lock_guard lock(mutex);
    flowing = on;
    changed.notify_all();
  }
};

class TapSource : public FrameSource {
 public:
  explicit TapSource(std::shared_ptr<Tap> tap) : tap_(std::move(tap)) {}
  std::string describe() const override { return "tap source"; }
  bool is_live() const override { return false; }
  std::shared_ptr<const CameraModel> camera_model() const override { return nullptr; }
  SourceStatus next(Frame& frame) override {
    std::unique_lock lock(tap_->mutex);
    tap_->changed.wait(lock, [&] { return tap_->flowing || tap_->interrupted; });
    if (tap_->interrupted) return SourceStatus::EndOfStream;
    frame = Frame::allocate(PixelFormat::RGB24, 2, 2);
    frame.meta.sequence = sequence_++;
    return SourceStatus::Frame;
  }
  void interrupt() override {
    std::lock_guard lock(tap_->mutex);
    tap_->interrupted = true;
    tap_->changed.notify_all();
  }

 private:
  std::shared_ptr<Tap> tap_;
  uint64_t sequence_ = 0;
};

struct MarkedAssets : StageAssets {
  std::string marker;
};

struct StageScript {
  std::string name = "stage";
  bool loads = true;                      // has an asset loader
  std::string hold_load_of;               // the loader waits on `gate` for a config with this marker
  std::shared_ptr<Gate> gate;
  std::string loader_throws_for;          // the loader throws for a config with this marker
  std::string refuses;                    // configure_loaded throws for a config with this marker
};

class LoadingStage : public Stage {
 public:
  LoadingStage(StageScript script, std::shared_ptr<Log> log) : script_(std::move(script)), log_(std::move(log)) {}
  std::string_view name() const override { return script_.name; }
  void configure(const Config& config) override { configure_loaded(config, nullptr); }

  StageAssetLoader asset_loader() const override {
    if (!script_.loads) return {};
    // Holds no reference to the stage, as the contract asks.
    return [script = script_, log = log_](const Config& config) -> std::shared_ptr<const StageAssets> {
      const std::string& marker = config.source.camera;
      log->record([&] {
        log->loaded.push_back(marker);
        log->loader_threads.push_back(std::this_thread::get_id());
      });
      if (marker == script.hold_load_of) script.gate->wait();
      if (marker == script.loader_throws_for) throw std::runtime_error(fmt::format("cannot read {}.mesh", marker));
      auto assets = std::make_shared<MarkedAssets>();
      assets->marker = marker;
      return assets;
    };
  }

  void configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) override {
    const auto* marked = dynamic_cast<const MarkedAssets*>(assets.get());
    log_->record([&] {
      log_->processing_thread = std::this_thread::get_id();
      log_->configured.emplace_back(config.source.camera, marked ? marked->marker : "(none)");
    });
    if (config.source.camera == script_.refuses)
      throw ConfigError(fmt::format("{} refuses '{}'", script_.name, config.source.camera));
  }

  void process(FrameContext&) noexcept override {
    log_->record([&] {
      ++log_->frames_processed;
      ++log_->processed_by[script_.name];
    });
  }

 private:
  StageScript script_;
  std::shared_ptr<Log> log_;
};

class RecordingSink : public FrameSink {
 public:
  explicit RecordingSink(std::shared_ptr<Log> log) : log_(std::move(log)) {}
  std::string describe() const override { return "recording sink"; }
  void run_started() noexcept override {
    log_->record([&] { log_->sink_events.push_back("started"); });
  }
  void consume(const FrameContext&) noexcept override {
    log_->record([&] {
      ++log_->frames_consumed;
      if (log_->sink_events.empty() || log_->sink_events.back() != "frame") log_->sink_events.push_back("frame");
    });
  }
  void flush() noexcept override {
    log_->record([&] { log_->sink_events.push_back("flush"); });
  }

 private:
  std::shared_ptr<Log> log_;
};

// A sink of a SinkSlot, named by its tag (the part of the config it was made from).
class TaggedSink : public FrameSink {
 public:
  TaggedSink(std::string tag, std::shared_ptr<Log> log) : tag_(std::move(tag)), log_(std::move(log)) {}
  ~TaggedSink() override { event("closed"); }
  std::string describe() const override { return "sink " + tag_; }
  void run_started() noexcept override { event("started"); }
  void consume(const FrameContext&) noexcept override {
    log_->record([&] { ++log_->consumed_by[tag_]; });
  }
  void flush() noexcept override { event("flush"); }

 private:
  void event(const std::string& what) {
    log_->record([&] { log_->slot_events.push_back(tag_ + " " + what); });
  }
  std::string tag_;
  std::shared_ptr<Log> log_;
};

// Two slots: "sinks.results" made from sinks.results.path (tag "results:<path>"), "sinks.png" from
// sinks.png.dir (tag "png:<dir>"); a disabled section makes none. A dir named "unwritable"
// cannot be opened.
std::vector<SinkSlot> tagged_slots(std::shared_ptr<Log> log) {
  std::vector<SinkSlot> slots;
  slots.push_back({"sinks.results", [](const Config& a, const Config& b) { return a.sinks.results == b.sinks.results; },
                   [log](const Config& c) -> std::unique_ptr<FrameSink> {
                     if (!c.sinks.results.enabled) return nullptr;
                     return std::make_unique<TaggedSink>("results:" + c.sinks.results.path.string(), log);
                   }});
  slots.push_back({"sinks.png", [](const Config& a, const Config& b) { return a.sinks.png == b.sinks.png; },
                   [log](const Config& c) -> std::unique_ptr<FrameSink> {
                     if (!c.sinks.png.enabled) return nullptr;
                     if (c.sinks.png.dir == "unwritable") throw std::runtime_error("cannot create unwritable");
                     return std::make_unique<TaggedSink>("png:" + c.sinks.png.dir.string(), log);
                   }});
  return slots;
}

Config with_sinks(Config config, const std::string& png_dir, const std::string& results_path = "r") {
  config.sinks.png.enabled = !png_dir.empty();
  config.sinks.png.dir = png_dir;
  config.sinks.results.enabled = true;  // named: a sink is off until the config names it
  config.sinks.results.path = results_path;
  return config;
}

struct Pipeline {
  std::shared_ptr<Log> log = std::make_shared<Log>();
  std::shared_ptr<Tap> tap = std::make_shared<Tap>();
  std::unique_ptr<PipelineRunner> runner;

  // `wrap`: which stages run only while the config asks for them (OptionalStage), by name.
  explicit Pipeline(std::vector<StageScript> scripts, Config first = marked("run"),
                    std::map<std::string, OptionalStage::Wanted> optional = {}) {
    StageFactory factory = [scripts, optional, log = log] {
      std::vector<std::unique_ptr<Stage>> stages;
      for (const auto& script : scripts) {
        auto make = [script, log] {
          log->record([&] { ++log->stages_made[script.name]; });
          return std::make_unique<LoadingStage>(script, log);
        };
        if (auto wanted = optional.find(script.name); wanted != optional.end())
          stages.push_back(std::make_unique<OptionalStage>(wanted->second, make));
        else
          stages.push_back(make());
      }
      return stages;
    };
    runner = std::make_unique<PipelineRunner>(std::make_unique<TapSource>(tap), factory,
                                              std::vector<std::unique_ptr<FrameSink>>{}, first);
    runner->make_sinks_at_start([log = log] {
      log->record([&] { ++log->sinks_made; });
      std::vector<std::unique_ptr<FrameSink>> sinks;
      sinks.push_back(std::make_unique<RecordingSink>(log));
      return sinks;
    });
  }
  ~Pipeline() {
    if (runner) {
      tap->set(true);
      runner->stop();
      runner->wait();
    }
  }
  size_t processed() {
    std::lock_guard lock(log->mutex);
    return log->frames_processed;
  }
  bool frames_flow_past(size_t count) {
    return log->wait_for([&] { return log->frames_processed > count; });
  }
  std::vector<std::pair<std::string, std::string>> configured() {
    std::lock_guard lock(log->mutex);
    return log->configured;
  }
  bool ever_configured_with(const std::string& marker) {
    for (const auto& [config, assets] : configured())
      if (config == marker || assets == marker) return true;
    return false;
  }
};

StageScript holding(std::shared_ptr<Gate> gate, std::string marker) {
  StageScript s;
  s.name = "slow";
  s.gate = std::move(gate);
  s.hold_load_of = std::move(marker);
  return s;
}

TEST(StageReload, SlowLoadRunsOnTheReloadingThreadWhileFramesFlow) {
  auto gate = std::make_shared<Gate>();
  Pipeline p({holding(gate, "next")});
  p.runner->start();
  ASSERT_TRUE(p.frames_flow_past(0));

  bool accepted = false;
  std::string error;
  std::thread::id reloading_thread;
  std::thread reload([&] {
    reloading_thread = std::this_thread::get_id();
    accepted = p.runner->reconfigure(marked("next"), error);
  });
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->loaded.size() == 2; }));  // "run" at start, "next" now
  // The load is held; the processing thread goes on drawing frames under the running config.
  const size_t before = p.processed();
  EXPECT_TRUE(p.frames_flow_past(before + 20));
  EXPECT_FALSE(p.ever_configured_with("next"));
  gate->release();
  reload.join();
  EXPECT_TRUE(accepted) << error;
  EXPECT_EQ(error, "");

  std::lock_guard lock(p.log->mutex);
  ASSERT_EQ(p.log->loader_threads.size(), 2u);
  EXPECT_EQ(p.log->loader_threads[0], p.log->processing_thread);  // at start: nothing else to do yet
  EXPECT_EQ(p.log->loader_threads[1], reloading_thread);
  EXPECT_NE(p.log->loader_threads[1], p.log->processing_thread);
  // Swapped in with the assets loaded for that config.
  const std::vector<std::pair<std::string, std::string>> expected{{"run", "run"}, {"next", "next"}};
  EXPECT_EQ(p.log->configured, expected);
}

// The 10 s wait of old answered "refused" and then applied the config anyway once the processing
// thread came round. A reload refused for want of a frame boundary must stay refused.
TEST(StageReload, ReloadRefusedForWantOfAFrameBoundaryIsNeverAppliedLater) {
  Pipeline p({StageScript{}});
  p.runner->start();
  ASSERT_TRUE(p.frames_flow_past(2));
  p.tap->set(false);  // the camera stops delivering
  std::this_thread::sleep_for(50ms);  // what was queued has gone through

  std::string error;
  EXPECT_FALSE(p.runner->reconfigure(marked("late"), error, 100ms));
  EXPECT_NE(error.find("no frame boundary within 0.1 s"), std::string::npos) << error;

  p.tap->set(true);  // frames again: many frame boundaries pass
  const size_t before = p.processed();
  ASSERT_TRUE(p.frames_flow_past(before + 20));
  EXPECT_FALSE(p.ever_configured_with("late"));
  EXPECT_TRUE(p.runner->reconfigure(marked("later"), error)) << error;
  EXPECT_EQ(p.configured().back(), (std::pair<std::string, std::string>{"later", "later"}));
}

TEST(StageReload, NewerReloadSupersedesOneStillLoading) {
  auto gate = std::make_shared<Gate>();
  Pipeline p({holding(gate, "old")});
  p.runner->start();
  const std::shared_ptr<StageReloader> reloader = p.runner->reloader();
  ASSERT_TRUE(reloader);

  const uint64_t old_ticket = reloader->new_ticket();
  bool old_accepted = true;
  std::string old_error;
  std::thread old_reload([&] { old_accepted = reloader->reconfigure(old_ticket, marked("old"), old_error, 10s); });
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->loaded.size() == 2; }));  // "old" is loading

  std::string error;
  EXPECT_TRUE(reloader->reconfigure(reloader->new_ticket(), marked("new"), error, 10s)) << error;
  gate->release();  // the old load finishes after the newer reload was applied
  old_reload.join();
  EXPECT_FALSE(old_accepted);
  EXPECT_EQ(old_error, StageReloader::kSuperseded);

  const size_t before = p.processed();
  ASSERT_TRUE(p.frames_flow_past(before + 10));
  EXPECT_FALSE(p.ever_configured_with("old"));
  EXPECT_EQ(p.configured().back(), (std::pair<std::string, std::string>{"new", "new"}));
}

TEST(StageReload, NewTicketAnswersAReloadWaitingForItsFrameBoundary) {
  Pipeline p({StageScript{}});
  p.runner->start();
  ASSERT_TRUE(p.frames_flow_past(2));
  p.tap->set(false);
  std::this_thread::sleep_for(50ms);
  const std::shared_ptr<StageReloader> reloader = p.runner->reloader();

  const uint64_t ticket = reloader->new_ticket();
  bool accepted = true;
  std::string error;
  std::thread waiting([&] { accepted = reloader->reconfigure(ticket, marked("waiting"), error, 60s); });
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->loaded.size() == 2; }));
  std::this_thread::sleep_for(20ms);  // loaded and handed over, waiting for a frame
  const auto asked = std::chrono::steady_clock::now();
  reloader->new_ticket();  // a newer SIGHUP
  waiting.join();
  EXPECT_LT(std::chrono::steady_clock::now() - asked, 5s) << "answered at once, not after the 60 s";
  EXPECT_FALSE(accepted);
  EXPECT_EQ(error, StageReloader::kSuperseded);

  p.tap->set(true);
  const size_t before = p.processed();
  ASSERT_TRUE(p.frames_flow_past(before + 10));
  EXPECT_FALSE(p.ever_configured_with("waiting"));
}

TEST(StageReload, LoaderThatThrowsRefusesAndTheStagesNeverSeeTheConfig) {
  StageScript script;
  script.loader_throws_for = "bad";
  Pipeline p({script});
  p.runner->start();
  std::string error;
  EXPECT_FALSE(p.runner->reconfigure(marked("bad"), error));
  EXPECT_EQ(error, "stage stage: cannot read bad.mesh");
  const size_t before = p.processed();
  ASSERT_TRUE(p.frames_flow_past(before + 10));
  EXPECT_FALSE(p.ever_configured_with("bad"));
}

// A stage that refuses the swapped-in config: the stages before it return to the running config
// with the assets it was loaded into, without loading them again.
TEST(StageReload, RefusedReloadPutsTheStagesBackOnTheirRunningAssets) {
  StageScript first;
  first.name = "first";
  StageScript picky;
  picky.name = "picky";
  picky.loads = false;
  picky.refuses = "refused";
  Pipeline p({first, picky});
  p.runner->start();
  std::string error;
  EXPECT_FALSE(p.runner->reconfigure(marked("refused"), error));
  EXPECT_EQ(error, "stage picky: picky refuses 'refused'");
  const std::vector<std::pair<std::string, std::string>> expected{
      {"run", "run"}, {"run", "(none)"},             // start
      {"refused", "refused"}, {"refused", "(none)"},  // the swap, refused by picky
      {"run", "run"}, {"run", "(none)"}};             // back
  EXPECT_EQ(p.configured(), expected);
  std::lock_guard lock(p.log->mutex);
  EXPECT_EQ(p.log->loaded, (std::vector<std::string>{"run", "refused"}));  // "run" was not loaded again
}

TEST(StageReload, SinksAreMadeAfterTheStagesAndStartedBeforeTheirFirstFrame) {
  Pipeline p({StageScript{}});
  p.runner->start();
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->frames_consumed >= 3; }));
  std::lock_guard lock(p.log->mutex);
  EXPECT_EQ(p.log->sinks_made, 1);
  ASSERT_GE(p.log->sink_events.size(), 2u);
  EXPECT_EQ(p.log->sink_events[0], "started");
  EXPECT_EQ(p.log->sink_events[1], "frame");
}

// A setup whose stage refuses its config (a bad mesh) never opens an output.
TEST(StageReload, FailedStartMakesNoSinks) {
  StageScript script;
  script.refuses = "run";
  Pipeline p({script});
  EXPECT_THROW(p.runner->start(), ConfigError);
  std::lock_guard lock(p.log->mutex);
  EXPECT_EQ(p.log->sinks_made, 0);
  EXPECT_TRUE(p.log->sink_events.empty());
}

TEST(StageReload, ReloadAfterTheStreamEndedIsRefused) {
  Pipeline p({StageScript{}});
  p.runner->start();
  ASSERT_TRUE(p.frames_flow_past(0));
  p.runner->stop();
  p.runner->wait();
  std::string error;
  EXPECT_FALSE(p.runner->reconfigure(marked("after"), error));
  EXPECT_NE(error.find("stream has ended"), std::string::npos) << error;
  EXPECT_FALSE(p.ever_configured_with("after"));
}

size_t consumed_by(Pipeline& p, const std::string& tag) {
  std::lock_guard lock(p.log->mutex);
  return p.log->consumed_by[tag];
}
std::vector<std::string> slot_events(Pipeline& p) {
  std::lock_guard lock(p.log->mutex);
  return p.log->slot_events;
}

// A re-pointed sink: the old one gets every frame before the boundary and is flushed and closed
// before the new one starts, which gets every frame after it; the sink whose part did not change
// runs on untouched and gets every frame.
TEST(StageReload, ChangedSinkIsReplacedAtAFrameBoundaryAndTheOthersRunOnUntouched) {
  Pipeline p({StageScript{}}, with_sinks(marked("run"), "a"));
  p.runner->use_sink_slots(tagged_slots(p.log));
  p.runner->start();
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:a"] >= 5; }));
  std::string error;
  Config replaced;
  ASSERT_TRUE(p.runner->reloader()->reconfigure(p.runner->reloader()->new_ticket(), with_sinks(marked("next"), "b"),
                                                error, 10s, &replaced))
      << error;
  EXPECT_EQ(replaced, with_sinks(marked("run"), "a"));
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:b"] >= 5; }));
  // Each sink starts on its own thread, so the two first starts may come in either order; the
  // replaced sink's events and the new one's start are ordered.
  std::vector<std::string> events = slot_events(p);
  const auto results_started = std::find(events.begin(), events.end(), "results:r started");
  ASSERT_NE(results_started, events.end());
  events.erase(results_started);
  const std::vector<std::string> expected{"png:a started", "png:a flush", "png:a closed", "png:b started"};
  EXPECT_EQ(events, expected);
  p.runner->stop();
  p.runner->wait();
  EXPECT_EQ(consumed_by(p, "png:a") + consumed_by(p, "png:b"), consumed_by(p, "results:r"));
}

TEST(StageReload, SinkTheReloadedConfigNoLongerAsksForIsFlushedAndClosed) {
  Pipeline p({StageScript{}}, with_sinks(marked("run"), "a"));
  p.runner->use_sink_slots(tagged_slots(p.log));
  p.runner->start();
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:a"] >= 3; }));
  std::string error;
  ASSERT_TRUE(p.runner->reconfigure(with_sinks(marked("next"), ""), error)) << error;
  ASSERT_TRUE(p.log->wait_for([&] {
    return std::find(p.log->slot_events.begin(), p.log->slot_events.end(), "png:a closed") != p.log->slot_events.end();
  }));
  const size_t a = consumed_by(p, "png:a"), results = consumed_by(p, "results:r");
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["results:r"] >= results + 5; }));
  EXPECT_EQ(consumed_by(p, "png:a"), a);
  // Added back by a later reload: a new sink, from then on.
  ASSERT_TRUE(p.runner->reconfigure(with_sinks(marked("again"), "a"), error)) << error;
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:a"] >= a + 3; }));
  const std::vector<std::string> events = slot_events(p);
  EXPECT_EQ(std::count(events.begin(), events.end(), "png:a started"), 2);
}

// A sink that cannot be made refuses the whole reload: the stages never see the config and the
// running sinks stay.
TEST(StageReload, SinkThatCannotBeMadeRefusesTheReload) {
  Pipeline p({StageScript{}}, with_sinks(marked("run"), "a"));
  p.runner->use_sink_slots(tagged_slots(p.log));
  p.runner->start();
  // Both sinks have started (each on its own thread).
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:a"] >= 1 && p.log->consumed_by["results:r"] >= 1; }));
  std::string error;
  EXPECT_FALSE(p.runner->reconfigure(with_sinks(marked("bad"), "unwritable", "r2"), error));
  EXPECT_EQ(error, "sinks.png: cannot create unwritable");
  const size_t a = consumed_by(p, "png:a");
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->consumed_by["png:a"] >= a + 5; }));
  EXPECT_FALSE(p.ever_configured_with("bad"));
  std::vector<std::string> events = slot_events(p);
  // The two running sinks start on their own threads, in either order, before the reload; the
  // results sink made for it was closed without ever starting (its output stays as it was).
  ASSERT_EQ(events.size(), 3u);
  std::sort(events.begin(), events.begin() + 2);
  EXPECT_EQ(events, (std::vector<std::string>{"png:a started", "results:r started", "results:r2 closed"}));
}

// The stage "optional" runs while the config's marker starts with "on": a reload adds it (a fresh
// one, since frames went by without it), removes it, and a reload refused by a later stage puts it
// back as it was. Its loader runs only for the configs that want it.
TEST(StageReload, OptionalStageComesAndGoesWithTheConfig) {
  StageScript always;
  always.name = "always";
  StageScript optional;
  optional.name = "optional";
  StageScript picky;
  picky.name = "picky";
  picky.loads = false;
  picky.refuses = "off-refused";
  const auto on = [](const Config& c) { return c.source.camera.rfind("on", 0) == 0; };
  Pipeline p({always, optional, picky}, marked("off"), {{"optional", on}});
  p.runner->start();
  const auto processed_by = [&](const std::string& stage) {
    std::lock_guard lock(p.log->mutex);
    return p.log->processed_by[stage];
  };
  const auto loaded = [&] {
    std::lock_guard lock(p.log->mutex);
    return p.log->loaded;
  };
  ASSERT_TRUE(p.frames_flow_past(10));
  EXPECT_EQ(processed_by("optional"), 0u);
  EXPECT_EQ(loaded(), (std::vector<std::string>{"off"}));  // "always" only

  std::string error;
  ASSERT_TRUE(p.runner->reconfigure(marked("on"), error)) << error;
  EXPECT_EQ(loaded(), (std::vector<std::string>{"off", "on", "on"}));
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->processed_by["optional"] >= 5; }));

  EXPECT_FALSE(p.runner->reconfigure(marked("off-refused"), error));
  EXPECT_EQ(error, "stage picky: picky refuses 'off-refused'");
  const size_t before_refused = processed_by("optional");
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->processed_by["optional"] >= before_refused + 5; }));

  ASSERT_TRUE(p.runner->reconfigure(marked("off"), error)) << error;
  const size_t always_frames = processed_by("always"), optional_frames = processed_by("optional");
  ASSERT_TRUE(p.log->wait_for([&] { return p.log->processed_by["always"] >= always_frames + 10; }));
  EXPECT_EQ(processed_by("optional"), optional_frames);

  std::lock_guard lock(p.log->mutex);
  // Made by the factory, then once more when switched on after frames went by without it; the
  // refused reload put the running one back.
  EXPECT_EQ(p.log->stages_made["optional"], 2);
  EXPECT_EQ(p.log->stages_made["always"], 1);
}

}  // namespace
}  // namespace arpipe
