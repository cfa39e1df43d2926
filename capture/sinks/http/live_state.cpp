#include "capture/sinks/http/live_state.h"

#include <nlohmann/json.hpp>

#include "capture/sinks/http/prometheus_writer.h"
#include "capture/sinks/results_sink.h"
#include "core/pipeline/pipeline_status_json.h"

namespace arpipe {

std::string live_state_json(const PipelineStatus& status, const FrameContext* latest, double frame_age_s,
                            bool camera_away, const HttpCounters& http) {
  using nlohmann::json;
  json j = pipeline_status_json(status);
  j["frame"] = latest ? ResultsSink::to_json(*latest) : json(nullptr);
  j["frame_age_s"] = latest ? json(frame_age_s) : json(nullptr);
  if (latest && (latest->pose.state == TrackState::Tracking || latest->pose.state == TrackState::Predicted)) {
    const Vec3 c = latest->pose.T_cam_world.inverse().translation();
    j["camera_position_world_m"] = {c[0], c[1], c[2]};
  }
  j["camera"]["away"] = camera_away;
  j["pipeline"]["recent_fps"] = http.recent_fps;
  j["http"] = {{"stream_clients", http.stream_clients},
               {"jpeg_encodes", http.jpeg_encodes},
               {"jpeg_encode_ms_mean", http.jpeg_encodes ? http.jpeg_encode_seconds / double(http.jpeg_encodes) * 1e3 : 0.0},
               {"frames_not_encoded", http.frames_not_encoded},
               {"requests", http.requests}};
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string live_metrics_text(const PipelineStatus& status, bool camera_away, const HttpCounters& http) {
  const PipelineMetrics& m = status.metrics;
  PrometheusWriter w;
  w.family("arpipe_frames_in_total", "counter", "Frames the source delivered.");
  w.sample("arpipe_frames_in_total", double(m.frames_in));
  w.family("arpipe_frames_out_total", "counter", "Frames handed to the sinks.");
  w.sample("arpipe_frames_out_total", double(m.frames_out));
  w.family("arpipe_queue_drops_total", "counter", "Frames dropped because processing fell behind a live camera.");
  w.sample("arpipe_queue_drops_total", double(m.queue_drops));
  w.family("arpipe_sequence_gaps_total", "counter", "Frames the camera's sequence numbers say were lost before arpiped.");
  w.sample("arpipe_sequence_gaps_total", double(m.sequence_gaps));
  w.family("arpipe_source_retries_total", "counter", "Times the source had no frame (timeout, camera away) and was asked again.");
  w.sample("arpipe_source_retries_total", double(m.source_retries));
  w.family("arpipe_frames_by_track_state_total", "counter", "Frames by the tracker's result.");
  w.sample("arpipe_frames_by_track_state_total", {{"state", "tracking"}}, double(m.frames_tracked));
  w.sample("arpipe_frames_by_track_state_total", {{"state", "predicted"}}, double(m.frames_predicted));
  w.sample("arpipe_frames_by_track_state_total", {{"state", "lost"}}, double(m.frames_lost));
  w.family("arpipe_frames_overlapped_total", "counter",
           "Frames whose tracking ran on the helper thread while the frame before rendered (pipeline.overlap_first_stage).");
  w.sample("arpipe_frames_overlapped_total", double(m.frames_overlapped));
  w.family("arpipe_stage_runs_total", "counter", "Frames each stage was given, skips included.");
  for (const auto& [name, stats] : m.stages) w.sample("arpipe_stage_runs_total", {{"stage", name}}, double(stats.runs));
  w.family("arpipe_stage_skips_total", "counter", "Frames a stage returned at once for, by reason.");
  for (const auto& [name, stats] : m.stages)
    for (const auto& [reason, count] : stats.skips)
      w.sample("arpipe_stage_skips_total", {{"stage", name}, {"reason", reason}}, double(count));
  w.family("arpipe_stage_duration_seconds", "histogram", "Time each stage took per frame.");
  for (const auto& [name, stats] : m.stages) w.histogram("arpipe_stage_duration_seconds", {{"stage", name}}, stats.seconds);
  w.family("arpipe_frame_latency_seconds", "histogram",
           "From the end of the exposure (a replay: the frame's arrival) to the hand-over to the sinks.");
  w.histogram("arpipe_frame_latency_seconds", {}, m.latency_seconds);
  w.family("arpipe_sink_frames_total", "counter", "Frames each sink has taken.");
  for (const SinkStats& s : status.sinks) w.sample("arpipe_sink_frames_total", {{"sink", s.key}}, double(s.consumed));
  w.family("arpipe_sink_dropped_frames_total", "counter", "Frames a sink's queue dropped because the sink fell behind.");
  for (const SinkStats& s : status.sinks) w.sample("arpipe_sink_dropped_frames_total", {{"sink", s.key}}, double(s.dropped));
  w.family("arpipe_sink_queued_frames", "gauge", "Frames waiting for each sink.");
  for (const SinkStats& s : status.sinks) w.sample("arpipe_sink_queued_frames", {{"sink", s.key}}, double(s.queued));
  w.family("arpipe_camera_connected", "gauge", "1 while the source delivers (a live camera is present), else 0.");
  w.sample("arpipe_camera_connected", status.source_connected && !camera_away ? 1 : 0);
  if (status.capture) {
    w.family("arpipe_capture_copies_total", "counter",
             "Full copies of a frame out of the camera driver's buffers (one a frame when the driver's memory cannot be imported).");
    w.sample("arpipe_capture_copies_total", double(status.capture->copies));
    w.family("arpipe_capture_frame_allocations_total", "counter",
             "Camera frames whose memory was allocated rather than reused from a frame the sinks were done with.");
    w.sample("arpipe_capture_frame_allocations_total", double(status.capture->frame_allocations));
  }
  w.family("arpipe_source_live", "gauge", "1 for a live camera, 0 for a replay.");
  w.sample("arpipe_source_live", status.live ? 1 : 0);
  w.family("arpipe_uptime_seconds", "gauge", "Seconds since the pipeline started.");
  w.sample("arpipe_uptime_seconds", status.uptime_seconds);
  w.family("arpipe_http_stream_clients", "gauge", "MJPEG clients connected.");
  w.sample("arpipe_http_stream_clients", http.stream_clients);
  w.family("arpipe_http_jpeg_encodes_total", "counter", "Frames encoded as JPEG for the streams (once per frame, none without clients).");
  w.sample("arpipe_http_jpeg_encodes_total", double(http.jpeg_encodes));
  w.family("arpipe_http_jpeg_encode_seconds_total", "counter", "Time spent encoding those frames.");
  w.sample("arpipe_http_jpeg_encode_seconds_total", http.jpeg_encode_seconds);
  w.family("arpipe_http_frames_not_encoded_total", "counter", "Frames not encoded because no stream client watched.");
  w.sample("arpipe_http_frames_not_encoded_total", double(http.frames_not_encoded));
  w.family("arpipe_http_requests_total", "counter", "HTTP requests answered.");
  w.sample("arpipe_http_requests_total", double(http.requests));
  w.family("arpipe_http_stream_latency_seconds", "histogram",
           "From the end of the exposure (a replay: the frame's arrival) to the frame's last byte handed to a stream client's socket.");
  w.histogram("arpipe_http_stream_latency_seconds", {}, http.stream_latency_seconds);
  w.family("process_cpu_seconds_total", "counter", "User and system CPU time of the whole process, every thread's.");
  w.sample("process_cpu_seconds_total", http.process_cpu_seconds);
  w.family("arpipe_cpu_seconds_total", "counter",
           "CPU time by part of the pipeline: processing (the stages), helper (tracking ahead), gl (llvmpipe's "
           "rasteriser), capture, sinks, other; a thread that ended loses its time since the scrape before.");
  for (const auto& [part, seconds] : http.cpu_seconds_by_part) w.sample("arpipe_cpu_seconds_total", {{"part", part}}, seconds);
  return w.text();
}

}  // namespace arpipe
