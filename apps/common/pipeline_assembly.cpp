#include "apps/common/pipeline_assembly.h"

#include <fmt/format.h>

#include "capture/live/live_source.h"
#include "capture/replay_source.h"
#include "capture/sinks/png_sink.h"
#include "capture/sinks/recording_sink.h"
#include "capture/sinks/results_sink.h"
#include "capture/sinks/y4m_sink.h"
#include "core/light/light_stage.h"
#include "core/motion/motion_stage.h"
#include "core/track/tag_tracker.h"
#include "render/lens/lens_mode.h"
#include "render/gl_stages.h"

namespace arpipe {

std::unique_ptr<FrameSource> make_source(const Config& config) {
  if (config.source.type == "replay") return std::make_unique<ReplaySource>(config.source);
  if (config.source.type == "v4l2" || config.source.type == "libcamera") return make_live_source(config.source);
  throw ConfigError(fmt::format("{}: source.type \"{}\" is not supported (expected \"replay\", \"v4l2\" or \"libcamera\")",
                                config.file.string(), config.source.type));
}

std::vector<std::unique_ptr<FrameSink>> make_sinks(const Config& config) {
  std::vector<std::unique_ptr<FrameSink>> sinks;
  const auto& s = config.sinks;
  if (s.results.enabled) sinks.push_back(std::make_unique<ResultsSink>(s.results));
  if (s.png.enabled) sinks.push_back(std::make_unique<PngSink>(s.png));
  if (s.y4m.enabled) sinks.push_back(std::make_unique<Y4mSink>(s.y4m));
  if (s.recording.enabled) sinks.push_back(std::make_unique<RecordingSink>(s.recording));
  return sinks;
}

StageFactory make_stage_factory(const Config& config) {
  // The motion stage needs the tracker's poses. It stays out of the list when disabled (a config
  // reload cannot add it; it can switch it off, since the stage checks motion.enabled per frame).
  const bool motion = config.track.enabled && config.motion.enabled;
  // Likewise the light stage: only for a probe or the sun (the fixed light needs no stage).
  const bool light = config.light.source != "fixed";
  return [motion, light] {
    std::vector<std::unique_ptr<Stage>> stages;
    stages.push_back(std::make_unique<TagTracker>());
    if (motion) stages.push_back(std::make_unique<MotionStage>());
    if (light) stages.push_back(std::make_unique<LightStage>());
    for (auto& stage : make_gl_stages()) stages.push_back(std::move(stage));
    return stages;
  };
}

std::unique_ptr<PipelineRunner> assemble_pipeline(const Config& config) {
  auto source = make_source(config);
  // A lens the renderer cannot reproduce in the configured render.lens mode is a setup error,
  // refused before streaming starts. "undistort" changes the output even without objects.
  const LensMode lens = parse_lens_mode(config.render.lens);
  const bool renders = config.render.enabled && !config.render.objects.empty();
  // Tracking and rendering project through the camera's model: without one nothing would land
  // where it belongs. (A model of another image size is refused by the source that loads it.)
  if ((renders || config.track.enabled) && !source->camera_model())
    throw ConfigError(fmt::format(
        "{}: no camera model: calibrate the camera (arpipe calib, docs/CALIBRATION.md) and set source.camera_model",
        source->describe()));
  if ((renders || lens == LensMode::Undistort) && source->camera_model()) {
    try {
      check_lens_for_mode(*source->camera_model(), lens);
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: camera model: {} (render.lens = \"{}\")", source->describe(), e.what(),
                                    lens_mode_name(lens)));
    }
  }
  // An exposure longer than the frame interval cannot happen; the configured fallback exposure
  // must be possible for this source.
  const std::optional<int64_t> interval = source->frame_interval_ns();
  if (config.track.enabled && config.motion.enabled && interval && config.motion.default_exposure_ns > *interval)
    throw ConfigError(fmt::format(
        "{}: motion.default_exposure_ms = {} is longer than the frame interval of {} ({} ms): an exposure cannot "
        "outlast its frame",
        config.file.empty() ? std::string("the config") : config.file.string(), double(config.motion.default_exposure_ns) * 1e-6,
        source->describe(), double(*interval) * 1e-6));
  // The outputs are opened by start() once the stages are configured: a setup that fails (a bad
  // mesh) or is stopped before then leaves the previous run's outputs as they were.
  auto runner = std::make_unique<PipelineRunner>(std::move(source), make_stage_factory(config),
                                                 std::vector<std::unique_ptr<FrameSink>>{}, config);
  runner->make_sinks_at_start([config] { return make_sinks(config); });
  return runner;
}

std::string describe_metrics(const PipelineMetrics& m) {
  std::string text = fmt::format(
      "{} frames in, {} out in {:.2f} s ({:.1f} frames/s); tracked {}, predicted {}, lost {}; sequence gaps {}, "
      "queue drops {}, source retries {}",
      m.frames_in, m.frames_out, m.wall_seconds, m.fps(), m.frames_tracked, m.frames_predicted, m.frames_lost,
      m.sequence_gaps, m.queue_drops, m.source_retries);
  for (const auto& [name, stats] : m.stages) {
    text += fmt::format("; {} {:.2f} ms/frame", name, stats.runs ? stats.total_ms / double(stats.runs) : 0.0);
    for (const auto& [reason, count] : stats.skips) text += fmt::format(" (skipped {}x: {})", count, reason);
  }
  return text;
}

}  // namespace arpipe
