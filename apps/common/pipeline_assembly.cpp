#include "apps/common/pipeline_assembly.h"

#include <fmt/format.h>

#include "capture/live/live_source.h"
#include "capture/panorama/panorama_source.h"
#include "capture/raw_colour_source.h"
#include "capture/replay_source.h"
#include "capture/sinks/gstreamer/gstreamer_sink.h"
#include "capture/sinks/http/http_sink.h"
#include "capture/sinks/png_sink.h"
#include "capture/sinks/recording_sink.h"
#include "capture/sinks/results_sink.h"
#include "capture/sinks/v4l2/v4l2_output_sink.h"
#include "capture/sinks/y4m_sink.h"
#include "core/light/light_stage.h"
#include "core/motion/motion_stage.h"
#include "core/pipeline/optional_stage.h"
#include "core/track/tag_tracker.h"
#include "render/lens/lens_mode.h"
#include "render/gl_stages.h"

namespace arpipe {

std::unique_ptr<FrameSource> make_source(const Config& config) {
  switch (config.source.type) {
    // Raw Bayer frames leave the source with their development decided ([source.raw]).
    case SourceType::Replay:
      return std::make_unique<RawColourSource>(std::make_unique<ReplaySource>(config.source), config.source.raw);
    case SourceType::V4l2:
    case SourceType::Libcamera:
      return std::make_unique<RawColourSource>(make_live_source(config.source), config.source.raw);
    case SourceType::Panorama:
      return std::make_unique<PanoramaSource>(config.source, config.light.source == LightSource::Panorama);
  }
  throw ConfigError(fmt::format("{}: source.type is not one of {}", config.file.string(),
                                choice_list(ChoiceNames<SourceType>(kSourceTypeNames))));
}

namespace {

// The slot of the sink that `make` makes from the part of the config that `part` picks.
template <typename Part, typename Make>
SinkSlot slot(std::string key, Part part, Make make) {
  return SinkSlot{std::move(key), [part](const Config& a, const Config& b) { return part(a) == part(b); },
                  [part, make](const Config& config) -> std::unique_ptr<FrameSink> {
                    if (!part(config).enabled) return nullptr;
                    return make(part(config));
                  }};
}

// The same for a sink S made from its part alone.
template <typename S, typename Part>
SinkSlot slot(std::string key, Part part) {
  return slot(std::move(key), part, [](const auto& section) { return std::make_unique<S>(section); });
}

}  // namespace

std::vector<SinkSlot> sink_slots(StatusProvider status) {
  std::vector<SinkSlot> slots;
  slots.push_back(slot<ResultsSink>("sinks.results", [](const Config& c) -> const auto& { return c.sinks.results; }));
  slots.push_back(slot<PngSink>("sinks.png", [](const Config& c) -> const auto& { return c.sinks.png; }));
  slots.push_back(slot<Y4mSink>("sinks.y4m", [](const Config& c) -> const auto& { return c.sinks.y4m; }));
  slots.push_back(slot<RecordingSink>("sinks.recording", [](const Config& c) -> const auto& { return c.sinks.recording; }));
  // The live outputs read the running pipeline's status (counters, sinks, camera) for /state and /metrics.
  slots.push_back(slot("sinks.http", [](const Config& c) -> const auto& { return c.sinks.http; },
                       [status](const HttpSinkConfig& http) { return std::make_unique<HttpSink>(http, status); }));
  slots.push_back(slot<V4l2OutputSink>("sinks.v4l2", [](const Config& c) -> const auto& { return c.sinks.v4l2; }));
  slots.push_back(slot<GstreamerSink>("sinks.gstreamer", [](const Config& c) -> const auto& { return c.sinks.gstreamer; }));
  return slots;
}

StageFactory make_stage_factory() {
  return [] {
    std::vector<std::unique_ptr<Stage>> stages;
    stages.push_back(std::make_unique<TagTracker>());
    // The motion stage needs the tracker's poses. A panorama's frames are instants (the still is
    // looked up at one pose): nothing to blur.
    stages.push_back(std::make_unique<OptionalStage>(
        [](const Config& c) { return c.track.enabled && c.motion.enabled && c.source.type != SourceType::Panorama; },
        [] { return std::make_unique<MotionStage>(); }));
    // The fixed light needs no stage: the renderer takes it from the config.
    stages.push_back(std::make_unique<OptionalStage>([](const Config& c) { return c.light.source != LightSource::Fixed; },
                                                     [] { return std::make_unique<LightStage>(); }));
    for (auto& stage : make_gl_stages()) stages.push_back(std::move(stage));
    return stages;
  };
}

std::unique_ptr<PipelineRunner> assemble_pipeline(const Config& config) {
  auto source = make_source(config);
  // A lens the renderer cannot reproduce in the configured render.lens mode is a setup error,
  // refused before streaming starts. "undistort" changes the output even without objects.
  const LensMode lens = config.render.lens;
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
  auto runner = std::make_unique<PipelineRunner>(std::move(source), make_stage_factory(),
                                                 std::vector<std::unique_ptr<FrameSink>>{}, config);
  runner->use_sink_slots(sink_slots(runner->status_provider()));
  return runner;
}

std::string describe_metrics(const PipelineMetrics& m) {
  std::string text = fmt::format(
      "{} frames in, {} out in {:.2f} s ({:.1f} frames/s); tracked {} ({} in the search window alone, {} still), "
      "predicted {}, lost {}; sequence gaps {}, queue drops {}, source retries {}",
      m.frames_in, m.frames_out, m.wall_seconds, m.fps(), m.frames_tracked, m.frames_tracked_in_window,
      m.frames_still, m.frames_predicted, m.frames_lost,
      m.sequence_gaps, m.queue_drops, m.source_retries);
  for (const auto& [name, stats] : m.stages) {
    text += fmt::format("; {} {:.2f} ms/frame", name, stats.runs ? stats.total_ms / double(stats.runs) : 0.0);
    for (const auto& [reason, count] : stats.skips) text += fmt::format(" (skipped {}x: {})", count, reason);
  }
  return text;
}

}  // namespace arpipe
