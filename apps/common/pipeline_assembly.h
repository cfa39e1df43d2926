// Builds a runnable pipeline (source, stages, sinks) from a Config; shared by arpiped and `arpipe replay`.
// Setup errors throw with messages that name the file and the place; nothing here runs per frame.
#pragma once

#include <memory>

#include "core/config/config.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe {

std::unique_ptr<FrameSource> make_source(const Config& config);
std::vector<std::unique_ptr<FrameSink>> make_sinks(const Config& config);
// track, motion (when tracking and motion are enabled), render, composite (in that order), created
// on the processing thread. The default config has both on.
StageFactory make_stage_factory(const Config& config = Config{});
// All of the above in a runner (not started); the sinks are made by its start(), after the stages.
std::unique_ptr<PipelineRunner> assemble_pipeline(const Config& config);

// Human-readable one-paragraph summary of what a finished run did, for logs and the CLI.
std::string describe_metrics(const PipelineMetrics& metrics);

}  // namespace arpipe
