// What the pipeline benchmarks share: one replay of a config through the whole pipeline without
// sinks, and a stage's mean time from its metrics.
#pragma once

#include <string>

#include "core/config/config.h"
#include "core/pipeline/pipeline_metrics.h"

namespace arpipe {

// Runs the config's source through every stage to its end (no sinks) and returns the metrics.
PipelineMetrics run_pipeline(const Config& config);
// Mean ms per frame of a stage, skipped frames included; 0 when it never ran.
double mean_stage_ms(const PipelineMetrics& metrics, const std::string& stage);

}  // namespace arpipe
