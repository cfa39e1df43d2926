// The texts the live outputs serve about the running daemon: /state (JSON: the latest frame's
// results line plus the daemon's counters) and /metrics (Prometheus text format 0.0.4).
#pragma once

#include <string>

#include "capture/sinks/http/http_counters.h"
#include "core/pipeline/frame_context.h"
#include "core/pipeline/pipeline_status.h"

namespace arpipe {

// latest: the newest frame, or null before the first; frame_age_s: how long ago it was published;
// camera_away: the placeholder is showing.
std::string live_state_json(const PipelineStatus& status, const FrameContext* latest, double frame_age_s,
                            bool camera_away, const HttpCounters& http);

std::string live_metrics_text(const PipelineStatus& status, bool camera_away, const HttpCounters& http);

}  // namespace arpipe
