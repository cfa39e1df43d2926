// Runs source -> stages -> sinks on three threads joined by bounded queues (DESIGN.md "Threads").
// The processing thread owns the stages (and so the GL context the render stages create).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "core/config/config.h"
#include "core/pipeline/bounded_queue.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/frame_source.h"
#include "core/pipeline/pipeline_metrics.h"
#include "core/pipeline/stage.h"

namespace arpipe {

// Creates the stages on the processing thread (GL contexts are bound to the thread that made them).
using StageFactory = std::function<std::vector<std::unique_ptr<Stage>>()>;

class PipelineRunner {
 public:
  PipelineRunner(std::unique_ptr<FrameSource> source, StageFactory stages,
                 std::vector<std::unique_ptr<FrameSink>> sinks, const Config& config);
  ~PipelineRunner();  // stops and joins

  // Starts the threads; blocks until the stages are configured. Throws if configuring failed.
  void start();
  // Ends the source, lets the queues drain through every stage and sink, flushes the sinks.
  void stop();
  // Blocks until the source ended and everything drained (or stop() was called).
  void wait();
  bool finished() const { return finished_; }

  // Validated on the processing thread between frames; false (with the reason) keeps the old one.
  bool reconfigure(const Config& config, std::string& error);

  PipelineMetrics metrics() const;
  std::string source_description() const { return source_->describe(); }
  std::string source_health() const { return source_->health(); }
  // False when the processing or the sink thread has been inside one frame for longer than
  // max_stall_ns (a hung stage or disk: the watchdog stops pinging, so systemd restarts the daemon).
  // Idle waiting is healthy.
  bool healthy(int64_t max_stall_ns) const;

 private:
  void capture_loop();
  void processing_loop();
  // The first stage that holds frames back (Stage::latency_frames() > 0), or stages_.size().
  size_t first_stage_with_latency() const;
  // Runs the stages from first_stage on, counts the frame in the metrics and hands it to the sinks.
  void finish_frame(FrameContext& ctx, size_t first_stage);
  void sink_loop();

  std::unique_ptr<FrameSource> source_;
  StageFactory stage_factory_;
  std::vector<std::unique_ptr<Stage>> stages_;
  std::vector<std::unique_ptr<FrameSink>> sinks_;
  Config config_;
  std::unique_ptr<BoundedQueue<FrameContext>> to_process_;
  std::unique_ptr<BoundedQueue<FrameContext>> to_sink_;
  std::thread capture_thread_, processing_thread_, sink_thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> finished_{false};
  std::atomic<int64_t> busy_since_ns_{0};       // 0 while the processing thread waits for a frame
  std::atomic<int64_t> sink_busy_since_ns_{0};  // 0 while the sink thread waits for a frame

  void apply_pending_reconfigure();
  struct PendingReconfigure;
  std::mutex reconfigure_mutex_;
  std::shared_ptr<PendingReconfigure> pending_reconfigure_;
  bool processing_ended_ = false;  // guarded by reconfigure_mutex_
  int64_t start_ns_ = 0;

  mutable std::mutex metrics_mutex_;
  PipelineMetrics metrics_;
};

}  // namespace arpipe
