// What a running pipeline says about itself while it runs: the metrics, each sink's queue, the
// source's state. Read by the live outputs (/state, /metrics) and the control socket.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/pipeline/frame_source.h"
#include "core/pipeline/pipeline_metrics.h"

namespace arpipe {

struct SinkStats {
  std::string key;          // its config key ("sinks.png"), or its description for unkeyed sinks
  uint64_t consumed = 0;    // frames it has taken
  uint64_t dropped = 0;     // frames its queue dropped because it fell behind (live sources only)
  uint64_t queued = 0;      // frames waiting for it now
};

struct PipelineStatus {
  PipelineMetrics metrics;
  std::vector<SinkStats> sinks;
  std::string source;            // its description
  std::string source_health;     // its counters, in words
  bool live = false;             // a camera (drops when behind) rather than a replay (blocks)
  bool source_connected = true;  // false while a live camera is away
  std::optional<CaptureCounts> capture;  // a camera's copies and allocations, when it counts them
  double uptime_seconds = 0;
};

using StatusProvider = std::function<PipelineStatus()>;

}  // namespace arpipe
