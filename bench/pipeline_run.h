// What the pipeline benchmarks share: one replay of a config through the whole pipeline without
// sinks, measured in its steady state, and a stage's mean time from its metrics.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/config/config.h"
#include "core/pipeline/pipeline_metrics.h"

namespace arpipe {

// The first frames of a run pay for its setup (the EGL context, the lens map, the first render
// targets, the threads' start): once per run, not per frame, so they are left out.
constexpr int64_t kWarmupFrames = 10;
// Pass-through runs this many times the frames of the runs it is compared with: it is ten times as
// fast or more, and 300 of its frames last a tenth of a second, which one stall of the machine
// could halve (seen: 1310 against 2952 frames/s in runs a minute apart).
constexpr int64_t kPassThroughFramesFactor = 10;

// Where a run's CPU went per frame, by part of the pipeline (thread_part, core/system/thread_cpu.h:
// the processing thread, its helper, the GL rasteriser's threads, capture, sinks, the rest), and
// how many cores were busy on average.
// Measured from the last warm-up frame to kCpuTailFrames before the last frame: the GL
// rasteriser's threads end with the run, and by then every thread is still running (the
// processing thread is at most the queues' depth ahead of the frames handed over).
struct CpuPerFrame {
  int64_t frames = 0;  // 0: not measured (a run of kCpuTailFrames frames or fewer, or no /proc)
  std::map<std::string, double> ms_by_part;
  double total_ms = 0;
  double cores_busy = 0;  // CPU seconds over wall seconds
};
constexpr int64_t kCpuTailFrames = 64;

// Runs the config's source through every stage (no sinks) for kWarmupFrames frames more than its
// pipeline.max_frames, and returns the metrics of the frames after those: frames_out, the stages'
// times and skips, the tracking counts, and wall_seconds from the last warm-up frame's hand-over
// to the last frame's. setup_seconds, when given, receives the time from building the pipeline to
// the first frame's hand-over: what a start costs before the first picture.
// cpu, when given, receives the run's CpuPerFrame.
PipelineMetrics run_pipeline(Config config, double* setup_seconds = nullptr, CpuPerFrame* cpu = nullptr);
// Mean ms per frame of a stage, skipped frames included; 0 when it never ran.
double mean_stage_ms(const PipelineMetrics& metrics, const std::string& stage);

}  // namespace arpipe
