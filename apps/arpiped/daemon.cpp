#include "apps/arpiped/daemon.h"

#include <pthread.h>
#include <signal.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <exception>

#include "apps/arpiped/systemd_notifier.h"
#include "apps/common/pipeline_assembly.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

log::Level level_from_name(const std::string& name) {
  if (name == "error") return log::Level::Error;
  if (name == "warning") return log::Level::Warning;
  if (name == "debug") return log::Level::Debug;
  return log::Level::Info;
}

// Signals are taken synchronously by the main thread; every pipeline thread inherits the mask.
sigset_t block_control_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  return set;
}

// The runner keeps the stages' config; `started` is only what the source and queues were built from.
void reload(PipelineRunner& runner, const DaemonOptions& options, const Config& started, SystemdNotifier& systemd) {
  systemd.reloading();
  log::info("SIGHUP: reloading {}", options.config_path.string());
  try {
    Config next = load_config(options.config_path, options.overrides);
    if (next.source != started.source || next.pipeline.queue_depth != started.pipeline.queue_depth)
      log::warn("{}: source and pipeline changes take effect at the next restart; stages and lighting now",
                options.config_path.string());
    std::string error;
    if (runner.reconfigure(next, error)) {
      log::set_max_level(level_from_name(next.pipeline.log_level));
      log::info("reload accepted");
    } else {
      log::error("reload refused, the running config stays: {}", error);
    }
  } catch (const std::exception& e) {
    log::error("reload refused, the running config stays: {}", e.what());
  }
  systemd.ready();
}

}  // namespace

int run_daemon(const DaemonOptions& options) {
  log::set_program_name("arpiped");
  const sigset_t signals = block_control_signals();
  SystemdNotifier systemd;

  Config config;
  std::unique_ptr<PipelineRunner> runner;
  try {
    config = load_config(options.config_path, options.overrides);
    log::set_max_level(level_from_name(config.pipeline.log_level));
    runner = assemble_pipeline(config);
    runner->start();
  } catch (const std::exception& e) {
    log::error("{}", e.what());
    return 2;
  }
  log::info("running {} with {}", options.config_path.string(), runner->source_description());
  systemd.ready();

  const int64_t watchdog_ns = systemd.watchdog_interval_ns();
  // Wake often enough to ping the watchdog at half its interval, and to report status.
  const int64_t tick_ns = watchdog_ns > 0 ? std::min<int64_t>(watchdog_ns / 2, 1'000'000'000) : 500'000'000;
  int64_t last_status_ns = 0;
  bool stopping = false;
  while (!runner->finished()) {
    timespec timeout{tick_ns / 1'000'000'000, tick_ns % 1'000'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if ((sig == SIGTERM || sig == SIGINT) && !stopping) {
      log::info("{}: draining the queues and flushing outputs", sig == SIGTERM ? "SIGTERM" : "SIGINT");
      systemd.stopping();
      stopping = true;
      runner->stop();
    } else if (sig == SIGHUP && !stopping) {
      reload(*runner, options, config, systemd);
    }
    // A stage or sink stuck inside one frame for a whole watchdog interval stops the pings.
    if (watchdog_ns > 0 && runner->healthy(watchdog_ns)) systemd.watchdog_ping();
    const int64_t now = monotonic_now_ns();
    if (now - last_status_ns > 2'000'000'000) {
      const auto m = runner->metrics();
      const std::string health = runner->source_health();
      systemd.status(fmt::format("{} frames, {:.1f} frames/s, tracked {}, predicted {}, lost {}, drops {}{}{}",
                                 m.frames_out, m.fps(), m.frames_tracked, m.frames_predicted, m.frames_lost,
                                 m.sequence_gaps + m.queue_drops, health.empty() ? "" : "; camera: ", health));
      last_status_ns = now;
    }
  }
  runner->wait();
  log::info("{}", describe_metrics(runner->metrics()));
  if (const std::string health = runner->source_health(); !health.empty()) log::info("camera: {}", health);
  return 0;
}

}  // namespace arpipe
