// Builds a runnable pipeline (source, stages, sinks) from a Config; shared by arpiped and `arpipe replay`.
// Setup errors throw with messages that name the file and the place; nothing here runs per frame.
#pragma once

#include <memory>

#include "core/config/config.h"
#include "core/pipeline/pipeline_runner.h"
#include "core/pipeline/sink_slot.h"

namespace arpipe {

std::unique_ptr<FrameSource> make_source(const Config& config);
// The sinks by config key (sinks.results, sinks.png, sinks.y4m, sinks.recording, sinks.http): each
// made when its section is enabled, and made anew by a reload that changes its section. The live
// outputs read the running pipeline's status through `status`.
std::vector<SinkSlot> sink_slots(StatusProvider status);
// track, motion (while tracking and motion are enabled), light (for any light.source but "fixed"),
// render, composite (in that order), created on the processing thread; the optional ones come and
// go with the config, reloads included.
StageFactory make_stage_factory();
// All of the above in a runner (not started); the sinks are made by its start(), after the stages.
std::unique_ptr<PipelineRunner> assemble_pipeline(const Config& config);

// Human-readable one-paragraph summary of what a finished run did, for logs and the CLI.
std::string describe_metrics(const PipelineMetrics& metrics);

}  // namespace arpipe
