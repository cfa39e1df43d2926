// What the pipeline benchmarks share (see pipeline_run.h).
#include "bench/pipeline_run.h"

#include <chrono>
#include <memory>
#include <vector>

#include "apps/common/pipeline_assembly.h"
#include "core/pipeline/frame_sink.h"
#include "core/system/thread_cpu.h"

namespace arpipe {
namespace {

// Counts what the stages recorded on each frame after the warm-up (count_frame, as the runner does
// for every frame). Runs on the sink thread; read after the runner has finished.
class SteadyStateSink final : public FrameSink {
 public:
  SteadyStateSink(std::shared_ptr<PipelineMetrics> metrics, int64_t measured_frames)
      : metrics_(std::move(metrics)), cpu_until_(measured_frames - kCpuTailFrames) {}
  std::string describe() const override { return "bench: steady state"; }
  void consume(const FrameContext& ctx) noexcept override {
    const auto now = std::chrono::steady_clock::now();
    if (seen_ == 0) first_ = now;
    if (++seen_ <= kWarmupFrames) {
      since_ = now;
      if (seen_ == kWarmupFrames && cpu_until_ > 0) cpu_before_ = threads_cpu();
      return;
    }
    PipelineMetrics& m = *metrics_;
    ++m.frames_out;
    if (int64_t(m.frames_out) == cpu_until_ && !cpu_before_.empty()) {
      cpu_.frames = cpu_until_;
      cpu_.ms_by_part = cpu_seconds_between(cpu_before_, threads_cpu(), thread_part);
      const double wall = std::chrono::duration<double>(now - since_).count();
      for (auto& [part, seconds] : cpu_.ms_by_part) {
        cpu_.total_ms += seconds * 1e3 / double(cpu_until_);
        cpu_.cores_busy += wall > 0 ? seconds / wall : 0;
        seconds *= 1e3 / double(cpu_until_);
      }
    }
    m.wall_seconds = std::chrono::duration<double>(now - since_).count();
    count_frame(m, ctx);
  }

  std::chrono::steady_clock::time_point first_frame() const { return first_; }
  const CpuPerFrame& cpu() const { return cpu_; }  // read after the run
  bool saw_a_frame() const { return seen_ > 0; }

 private:
  std::shared_ptr<PipelineMetrics> metrics_;
  int64_t seen_ = 0;
  std::chrono::steady_clock::time_point first_, since_;
  int64_t cpu_until_;
  std::vector<ThreadCpu> cpu_before_;
  CpuPerFrame cpu_;
};

}  // namespace

PipelineMetrics run_pipeline(Config config, double* setup_seconds, CpuPerFrame* cpu) {
  const int64_t measured_frames = config.pipeline.max_frames;
  config.pipeline.max_frames += kWarmupFrames;
  auto metrics = std::make_shared<PipelineMetrics>();
  std::vector<std::unique_ptr<FrameSink>> sinks;
  auto sink = std::make_unique<SteadyStateSink>(metrics, measured_frames);
  const SteadyStateSink& steady = *sink;  // owned by the runner, which outlives this use
  sinks.push_back(std::move(sink));
  const auto built = std::chrono::steady_clock::now();
  PipelineRunner runner(make_source(config), make_stage_factory(), std::move(sinks), config);
  runner.start();
  runner.wait();
  if (setup_seconds)
    *setup_seconds = steady.saw_a_frame() ? std::chrono::duration<double>(steady.first_frame() - built).count() : 0;
  if (cpu) *cpu = steady.cpu();
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
