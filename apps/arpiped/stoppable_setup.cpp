// arpiped's setup on a thread of its own (see stoppable_setup.h).
#include "apps/arpiped/stoppable_setup.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>

#include "apps/common/pipeline_assembly.h"
#include "core/log.h"

namespace arpipe {
namespace {

// How often the main thread looks whether the setup has finished while it waits for signals.
constexpr timespec kSetupPoll{0, 20'000'000};

// What the setup thread hands back; `done` is set last (release), read by the main thread (acquire).
struct SetupState {
  std::atomic<const char*> step{"reading the config"};
  std::atomic<bool> done{false};
  Config config;
  std::unique_ptr<PipelineRunner> runner;
  std::shared_ptr<LatestFrame> latest = std::make_shared<LatestFrame>();
  std::string error;  // empty: started
};

void set_up(const DaemonOptions& options, SetupState& state) {
  try {
    state.config = load_config(options.config_path, options.overrides);
    log::set_max_level(state.config.pipeline.log_level);
    state.step = "opening the source";
    auto runner = assemble_pipeline(state.config);
    runner->make_sinks_at_start([latest = state.latest] {
      std::vector<std::unique_ptr<FrameSink>> sinks;
      sinks.push_back(std::make_unique<LatestFrameSink>(latest));
      return sinks;
    });
    state.step = "loading the assets, configuring the stages and opening the outputs";
    runner->start();
    state.runner = std::move(runner);
  } catch (const std::exception& e) {
    state.error = e.what();
    if (state.error.empty()) state.error = "setup failed without a message";
  }
  state.done.store(true, std::memory_order_release);
}

}  // namespace

std::optional<StartedPipeline> set_up_stoppably(const DaemonOptions& options, const sigset_t& signals) {
  // Never unwound while the setup thread may still use it: a stop during setup leaves by _exit.
  SetupState state;
  std::thread setup([&options, &state] { set_up(options, state); });
  bool reload_requested = false, stop_requested = false;
  while (!state.done.load(std::memory_order_acquire)) {
    const int sig = sigtimedwait(&signals, nullptr, &kSetupPoll);
    if (sig == SIGHUP) {
      if (!reload_requested)
        log::info("SIGHUP during setup: reloading {} once the pipeline runs", options.config_path.string());
      reload_requested = true;
    } else if (sig == SIGTERM || sig == SIGINT) {
      if (state.done.load(std::memory_order_acquire)) {
        stop_requested = true;  // it finished just now: what started drains and flushes as usual
        break;
      }
      log::info("{} during setup ({}): exiting before the pipeline runs", sig == SIGTERM ? "SIGTERM" : "SIGINT",
                state.step.load());
      std::fflush(stderr);  // the log; never a FILE a stuck thread may hold
      _exit(kStoppedExitStatus);
    }
  }
  setup.join();
  if (!state.error.empty()) {
    log::error("{}", state.error);
    return std::nullopt;
  }
  return StartedPipeline{std::move(state.config), std::move(state.runner), state.latest, reload_requested, stop_requested};
}

}  // namespace arpipe
