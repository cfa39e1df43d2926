// A running pipeline's status as JSON: the camera (source, live, connected, health), the pipeline's
// counters and per-stage timings, and each sink's queue. Served by /state and `arpipe ctl status`.
#pragma once

#include <string>

#include "core/pipeline/pipeline_status.h"

namespace arpipe {

// One JSON object: {"camera": {...}, "pipeline": {...}, "sinks": [...]}.
std::string pipeline_status_json(const PipelineStatus& status);

}  // namespace arpipe
