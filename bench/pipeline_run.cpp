// What the pipeline benchmarks share (see pipeline_run.h).
#include "bench/pipeline_run.h"

#include "apps/common/pipeline_assembly.h"

namespace arpipe {

PipelineMetrics run_pipeline(const Config& config) {
  PipelineRunner runner(make_source(config), make_stage_factory(), {}, config);
  runner.start();
  runner.wait();
  return runner.metrics();
}

double mean_stage_ms(const PipelineMetrics& metrics, const std::string& stage) {
  const auto it = metrics.stages.find(stage);
  return it == metrics.stages.end() || it->second.runs == 0 ? 0 : it->second.total_ms / double(it->second.runs);
}

}  // namespace arpipe
