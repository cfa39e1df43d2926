// What arpiped does for each control request: status from the running pipeline, reload and set
// through the same background reload as SIGHUP (answered once it is applied or refused), a
// snapshot of the newest composited frame, and recording started and stopped as a set of the
// [sinks.recording] keys.
#pragma once

#include <memory>

#include "apps/arpiped/background_reloads.h"
#include "apps/arpiped/control_server.h"
#include "capture/sinks/latest_frame_sink.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe {

class DaemonControl {
 public:
  DaemonControl(PipelineRunner& runner, BackgroundReloads& reloads, std::shared_ptr<LatestFrame> latest)
      : runner_(runner), reloads_(reloads), latest_(std::move(latest)) {}

  ControlReply handle(const ControlRequest& request);

 private:
  // Starts a reload with these assignments and waits for its answer (at most a minute: a reload
  // that bakes longer is answered "still loading").
  ControlReply reload(const std::string& why, std::vector<std::string> assignments);
  ControlReply snapshot(const std::string& format);

  PipelineRunner& runner_;
  BackgroundReloads& reloads_;
  std::shared_ptr<LatestFrame> latest_;
};

}  // namespace arpipe
