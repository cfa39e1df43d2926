// arpiped's setup (config, source, stages, outputs) on a thread of its own while the main thread keeps
// answering signals, so that SIGTERM or SIGINT ends a setup that hangs (a FIFO) or runs long (a bake).
#pragma once

#include <signal.h>

#include <memory>
#include <optional>

#include "apps/arpiped/daemon.h"
#include "capture/sinks/latest_frame_sink.h"
#include "core/config/config.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe {

// Exit status of a daemon stopped by SIGTERM/SIGINT during its setup: stopped, like a running one.
constexpr int kStoppedExitStatus = 0;

struct StartedPipeline {
  Config config;
  std::unique_ptr<PipelineRunner> runner;  // started
  std::shared_ptr<LatestFrame> latest;     // the newest composited frame, for arpipe ctl snapshot
  bool reload_requested = false;           // a SIGHUP came during the setup
  bool stop_requested = false;             // SIGTERM/SIGINT came as the setup finished
};

// Loads the config and starts the pipeline it describes on a setup thread, while this thread waits
// on `signals` (blocked in every thread). Returns the started pipeline, or nullopt after logging a
// setup error. SIGTERM or SIGINT before the pipeline runs logs what the setup was doing and ends
// the process at once with kStoppedExitStatus (_exit: the setup thread may be stuck in a system
// call, and nothing half-built is unwound). A SIGHUP is remembered.
std::optional<StartedPipeline> set_up_stoppably(const DaemonOptions& options, const sigset_t& signals);

}  // namespace arpipe
