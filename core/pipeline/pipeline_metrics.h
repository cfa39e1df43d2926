// Counters and timings the pipeline reports (sd_notify STATUS, the results sink, benchmarks).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/pipeline/latency_histogram.h"

namespace arpipe {

struct StageStats {
  uint64_t runs = 0;
  double total_ms = 0;
  std::map<std::string, uint64_t> skips;  // skip reason -> count
  LatencyHistogram seconds;  // each run's time, skips included
};

struct PipelineMetrics {
  uint64_t frames_in = 0;         // frames the source delivered
  uint64_t frames_out = 0;        // frames handed to the sinks (each sink's own count: PipelineStatus)
  uint64_t sequence_gaps = 0;     // frames the source's sequence numbers say were lost
  uint64_t queue_drops = 0;       // frames dropped because processing fell behind (live only)
  uint64_t source_retries = 0;
  uint64_t frames_tracked = 0;
  uint64_t frames_predicted = 0;  // no detection, pose extrapolated (TrackState::Predicted)
  uint64_t frames_lost = 0;
  // Tracked frames whose tags were found in the window around the expected bundle alone
  // (track.search_window): the detector did not look at the rest of the frame.
  uint64_t frames_tracked_in_window = 0;
  // Tracked frames whose tags had not moved (track.still_px): the last detection's pose, kept.
  uint64_t frames_still = 0;
  // Frames whose first stage ran on the helper thread beside the previous frame's later stages
  // (pipeline.overlap_first_stage).
  uint64_t frames_overlapped = 0;
  std::map<std::string, StageStats> stages;
  // From the end of exposure (FrameContext::latency_origin_ns) to the frame's hand-over to the sinks.
  LatencyHistogram latency_seconds;
  double wall_seconds = 0;
  double fps() const { return wall_seconds > 0 ? frames_out / wall_seconds : 0; }
};

struct FrameContext;
// Adds what one processed frame recorded: each stage's time and skip, and the tracking counts.
void count_frame(PipelineMetrics& metrics, const FrameContext& ctx);

}  // namespace arpipe
