#include "apps/arpiped/daemon.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "apps/arpiped/background_reloads.h"
#include "apps/arpiped/control_server.h"
#include "apps/arpiped/daemon_control.h"
#include "apps/arpiped/stoppable_setup.h"
#include "apps/arpiped/systemd_notifier.h"
#include "apps/common/pipeline_assembly.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

// Signals are taken synchronously by the main thread; every other thread inherits the mask.
sigset_t block_control_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  return set;
}

}  // namespace

int run_daemon(const DaemonOptions& options) {
  log::set_program_name("arpiped");
  // A reader that goes away (a Y4M sink on a FIFO) is a write error (EPIPE) that the sink reports,
  // not the end of the daemon.
  signal(SIGPIPE, SIG_IGN);
  const sigset_t signals = block_control_signals();
  SystemdNotifier systemd;
  // From here on SIGTERM is answered (before, the default action ends the process).
  log::info("setting up from {}", options.config_path.string());

  std::optional<StartedPipeline> started = set_up_stoppably(options, signals);
  if (!started) return 2;
  PipelineRunner& runner = *started->runner;
  log::info("running {} with {}", options.config_path.string(), runner.source_description());
  BackgroundReloads reloads(options, started->config, runner.reloader(), systemd);
  DaemonControl control(runner, reloads, started->latest);
  std::unique_ptr<ControlServer> control_server;
  if (const auto path = control_socket_path(started->config.control.socket)) {
    try {
      control_server = std::make_unique<ControlServer>(*path, [&control](const ControlRequest& r) { return control.handle(r); });
    } catch (const std::exception& e) {
      // Asked for by name: a setup error. Systemd's runtime directory: the daemon runs without one.
      if (!started->config.control.socket.empty()) {
        log::error("{}", e.what());
        return 2;
      }
      log::warn("{}; running without a control socket", e.what());
    }
  }
  systemd.ready();
  if (started->reload_requested) reloads.start();

  const int64_t watchdog_ns = systemd.watchdog_interval_ns();
  // Wake often enough to ping the watchdog at half its interval, and to report status.
  const int64_t tick_ns = watchdog_ns > 0 ? std::min<int64_t>(watchdog_ns / 2, 1'000'000'000) : 500'000'000;
  int64_t last_status_ns = 0;
  bool stopping = false;
  const auto stop = [&](const char* why) {
    log::info("{}: draining the queues and flushing outputs", why);
    systemd.stopping();
    stopping = true;
    runner.stop();
  };
  if (started->stop_requested) stop("stopped as the setup finished");
  while (!runner.finished()) {
    timespec timeout{tick_ns / 1'000'000'000, tick_ns % 1'000'000'000};
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if ((sig == SIGTERM || sig == SIGINT) && !stopping) {
      stop(sig == SIGTERM ? "SIGTERM" : "SIGINT");
    } else if (sig == SIGHUP && !stopping) {
      reloads.start();
    }
    // A stage or sink stuck inside one frame for a whole watchdog interval stops the pings.
    if (watchdog_ns > 0 && runner.healthy(watchdog_ns)) systemd.watchdog_ping();
    const int64_t now = monotonic_now_ns();
    if (now - last_status_ns > 2'000'000'000) {
      const auto m = runner.metrics();
      const std::string health = runner.source_health();
      systemd.status(fmt::format("{} frames, {:.1f} frames/s, tracked {}, predicted {}, lost {}, drops {}{}{}",
                                 m.frames_out, m.fps(), m.frames_tracked, m.frames_predicted, m.frames_lost,
                                 m.sequence_gaps + m.queue_drops, health.empty() ? "" : "; camera: ", health));
      last_status_ns = now;
    }
  }
  runner.wait();
  log::info("{}", describe_metrics(runner.metrics()));
  if (const std::string health = runner.source_health(); !health.empty()) log::info("camera: {}", health);
  if (reloads.any_running()) {
    // Stuck on a file or still baking: it holds nothing the outputs need (they are flushed), and
    // unwinding the process under it could not be done safely.
    log::info("a reload was still loading; exiting without waiting for it");
    std::fflush(stderr);  // the log; never a FILE a stuck thread may hold
    _exit(0);
  }
  return 0;
}

}  // namespace arpipe
