#include "core/pipeline/pipeline_status_json.h"

#include <nlohmann/json.hpp>

namespace arpipe {

nlohmann::json pipeline_status_json(const PipelineStatus& status) {
  using nlohmann::json;
  json j;
  j["camera"] = {{"source", status.source},
                 {"live", status.live},
                 {"connected", status.source_connected},
                 {"health", status.source_health}};
  if (status.capture)
    j["camera"]["capture"] = {{"frames", status.capture->frames},
                              {"copies", status.capture->copies},
                              {"frame_allocations", status.capture->frame_allocations}};
  const PipelineMetrics& m = status.metrics;
  json stages = json::object();
  for (const auto& [name, stats] : m.stages) {
    json skips = json::object();
    for (const auto& [reason, count] : stats.skips) skips[reason] = count;
    stages[name] = {{"runs", stats.runs},
                    {"mean_ms", stats.runs ? stats.total_ms / double(stats.runs) : 0.0},
                    {"skips", skips}};
  }
  j["pipeline"] = {{"frames_in", m.frames_in},
                   {"frames_out", m.frames_out},
                   {"fps", m.fps()},
                   {"uptime_s", status.uptime_seconds},
                   {"queue_drops", m.queue_drops},
                   {"sequence_gaps", m.sequence_gaps},
                   {"source_retries", m.source_retries},
                   {"frames_tracked", m.frames_tracked},
                   {"frames_tracked_in_window", m.frames_tracked_in_window},
                   {"frames_still", m.frames_still},
                   {"frames_predicted", m.frames_predicted},
                   {"frames_lost", m.frames_lost},
                   {"frames_overlapped", m.frames_overlapped},
                   {"latency_ms_mean", m.latency_seconds.count()
                                           ? json(m.latency_seconds.sum() / double(m.latency_seconds.count()) * 1e3)
                                           : json(nullptr)},
                   {"stages", stages}};
  json sinks = json::array();
  for (const SinkStats& s : status.sinks)
    sinks.push_back({{"key", s.key}, {"consumed", s.consumed}, {"dropped", s.dropped}, {"queued", s.queued}});
  j["sinks"] = sinks;
  return j;
}

}  // namespace arpipe
