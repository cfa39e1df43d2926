// What the pipeline benchmarks share (see pipeline_run.h).
#include "bench/pipeline_run.h"

#include <chrono>
#include <memory>
#include <vector>

#include "apps/common/pipeline_assembly.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {
namespace {

// Counts what the stages recorded on each frame after the warm-up (count_frame, as the runner does
// for every frame). Runs on the sink thread; read after the runner has finished.
class SteadyStateSink final : public FrameSink {
 public:
  explicit SteadyStateSink(std::shared_ptr<PipelineMetrics> metrics) : metrics_(std::move(metrics)) {}
  std::string describe() const override { return "bench: steady state"; }
  void consume(const FrameContext& ctx) noexcept override {
    const auto now = std::chrono::steady_clock::now();
    if (seen_ == 0) first_ = now;
    if (++seen_ <= kWarmupFrames) {
      since_ = now;
      return;
    }
    PipelineMetrics& m = *metrics_;
    ++m.frames_out;
    m.wall_seconds = std::chrono::duration<double>(now - since_).count();
    count_frame(m, ctx);
  }

  std::chrono::steady_clock::time_point first_frame() const { return first_; }
  bool saw_a_frame() const { return seen_ > 0; }

 private:
  std::shared_ptr<PipelineMetrics> metrics_;
  int64_t seen_ = 0;
  std::chrono::steady_clock::time_point first_, since_;
};

}  // namespace

PipelineMetrics run_pipeline(Config config, double* setup_seconds) {
  config.pipeline.max_frames += kWarmupFrames;
  auto metrics = std::make_shared<PipelineMetrics>();
  std::vector<std::unique_ptr<FrameSink>> sinks;
  auto sink = std::make_unique<SteadyStateSink>(metrics);
  const SteadyStateSink& steady = *sink;  // owned by the runner, which outlives this use
  sinks.push_back(std::move(sink));
  const auto built = std::chrono::steady_clock::now();
  PipelineRunner runner(make_source(config), make_stage_factory(), std::move(sinks), config);
  runner.start();
  runner.wait();
  if (setup_seconds)
    *setup_seconds = steady.saw_a_frame() ? std::chrono::duration<double>(steady.first_frame() - built).count() : 0;
  const PipelineMetrics all = runner.metrics();
  PipelineMetrics measured = *metrics;
  measured.frames_in = all.frames_in;
  measured.queue_drops = all.queue_drops;
  return measured;
}

double mean_stage_ms(const PipelineMetrics& metrics, const std::string& stage) {
  const auto it = metrics.stages.find(stage);
  return it == metrics.stages.end() || it->second.runs == 0 ? 0 : it->second.total_ms / double(it->second.runs);
}

}  // namespace arpipe
