// A running pipeline's status as JSON: the camera (source, live, connected, health), the pipeline's
// counters and per-stage timings, and each sink's queue. Served by /state and `arpipe ctl status`.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include "core/pipeline/pipeline_status.h"

namespace arpipe {

// One JSON object: {"camera": {...}, "pipeline": {...}, "sinks": [...]}; callers add their own
// parts and dump it (with the replace error handler: a source description may hold any bytes).
nlohmann::json pipeline_status_json(const PipelineStatus& status);

}  // namespace arpipe
