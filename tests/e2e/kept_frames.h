// The e2e tests' way to run a config through the whole pipeline in this process and keep every
// composited frame with what the stages said of it.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/common/pipeline_assembly.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/pipeline_runner.h"

namespace arpipe::kept_frames {

namespace fs = std::filesystem;

inline const fs::path kConfigs = fs::path(ARPIPE_SOURCE_DIR) / "configs";
inline const fs::path kBuild = fs::path(ARPIPE_BINARY_DIR);

// What one composited frame showed, and what the render stage said of it.
struct Shown {
  uint64_t index = 0;
  Frame output;
  bool drawn = false;
  VirtualLayerTexture layer;
  int blur_samples = 0;
  std::string render_skip;
  PoseEstimate pose;  // what tracking gave
};

class KeepFrames final : public FrameSink {
 public:
  explicit KeepFrames(std::vector<Shown>& frames) : frames_(frames) {}
  std::string describe() const override { return "test:keep"; }
  void consume(const FrameContext& ctx) noexcept override {
    Shown shown{ctx.input_index, ctx.output, ctx.virtual_layer_drawn, ctx.virtual_layer, ctx.blur_samples, {}, ctx.pose};
    for (const StageTiming& timing : ctx.timings)
      if (timing.stage == "render") shown.render_skip = timing.skipped;
    frames_.push_back(std::move(shown));
  }

 private:
  std::vector<Shown>& frames_;
};

// metrics: where to put the run's counters, when wanted.
inline std::vector<Shown> run(const fs::path& config_file, const fs::path& capture, int frames,
                              std::vector<std::string> overrides, PipelineMetrics* metrics = nullptr) {
  for (const std::string& o :
       {std::string("source.path=\"") + capture.string() + "\"", std::string("source.pacing=\"fast\""),
        std::string("sinks.png.enabled=false"), std::string("sinks.y4m.enabled=false"),
        std::string("sinks.results.enabled=false"), std::string("pipeline.log_level=\"warning\""),
        "pipeline.max_frames=" + std::to_string(frames)})
    overrides.push_back(o);
  const Config config = load_config(config_file, overrides);
  std::vector<Shown> shown;
  std::vector<std::unique_ptr<FrameSink>> sinks;
  sinks.push_back(std::make_unique<KeepFrames>(shown));
  PipelineRunner runner(make_source(config), make_stage_factory(), std::move(sinks), config);
  runner.start();
  runner.wait();
  if (metrics) *metrics = runner.metrics();
  return shown;
}

}  // namespace arpipe::kept_frames
