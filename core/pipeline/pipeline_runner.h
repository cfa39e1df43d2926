// Runs source -> stages -> sinks on three threads joined by bounded queues (docs/DESIGN.md "Threads").
// The processing thread owns the stages (and so the GL context the render stages create).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "core/config/config.h"
#include "core/pipeline/bounded_queue.h"
#include "core/pipeline/frame_pool.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/frame_source.h"
#include "core/pipeline/pipeline_metrics.h"
#include "core/pipeline/pipeline_status.h"
#include "core/pipeline/sink_worker.h"
#include "core/pipeline/sink_slot.h"
#include "core/pipeline/stage.h"
#include "core/pipeline/stage_reloader.h"
#include "core/pipeline/stereo_packer.h"

namespace arpipe {

// Creates the stages on the processing thread (GL contexts are bound to the thread that made them).
using StageFactory = std::function<std::vector<std::unique_ptr<Stage>>()>;
using SinkFactory = std::function<std::vector<std::unique_ptr<FrameSink>>()>;

class PipelineRunner {
 public:
  PipelineRunner(std::unique_ptr<FrameSource> source, StageFactory stages,
                 std::vector<std::unique_ptr<FrameSink>> sinks, const Config& config);
  ~PipelineRunner();  // stops and joins

  // Sinks that start() makes once every stage is configured, after those given to the constructor:
  // a setup that fails (or is stopped) while loading its assets has not opened a single output.
  void make_sinks_at_start(SinkFactory factory) { sink_factory_ = std::move(factory); }
  // Sinks by config key, made by start() like those above (after them) from the config it runs,
  // and made anew by a reload that changes their part of the config (the running one flushed and
  // closed first, at the frame boundary where the new config takes over).
  void use_sink_slots(std::vector<SinkSlot> slots) { sink_slots_ = std::move(slots); }

  // Starts the threads; blocks until the stages are configured (their assets loaded on the
  // processing thread, which has nothing else to do yet) and the sinks made. Throws if that failed.
  void start();
  // Ends the source, lets the queues drain through every stage and sink, flushes the sinks.
  void stop();
  // Blocks until the source ended and everything drained (or stop() was called).
  void wait();
  bool finished() const { return finished_; }

  // A reload: the stages' assets are loaded (and changed sinks made) on the calling thread, then
  // swapped in by the processing thread at a frame boundary (StageReloader::reconfigure); false
  // (with the reason) keeps the running config, and a refused reload is never applied later. Only
  // after start(). pipeline.queue_depth and the source are taken once, by start().
  bool reconfigure(const Config& config, std::string& error,
                   std::chrono::milliseconds boundary_timeout = kReconfigureBoundaryTimeout);
  // For a reload from another thread that must not keep the runner alive (it may be stuck loading).
  // Null before start().
  std::shared_ptr<StageReloader> reloader() const { return reloader_; }
  static constexpr std::chrono::milliseconds kReconfigureBoundaryTimeout{10'000};

  PipelineMetrics metrics() const;
  // The metrics, each sink's queue and the source's state; thread-safe, for the live outputs.
  PipelineStatus status() const;
  StatusProvider status_provider() const {
    return [this] { return status(); };
  }
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
  // On the sink thread, between two frames: closes and starts the sinks a reload changed.
  void swap_sinks(SinkSwap& swap);
  std::unique_ptr<SinkWorker> make_worker(std::string key, std::unique_ptr<FrameSink> sink) const;
  // The most camera images the running pipeline holds at once: what the frame pool keeps.
  size_t frames_in_flight_bound(size_t sink_count) const;

  // What the sink thread takes, in order: a frame, or the sinks a reload changed.
  struct ToSink {
    FrameContext frame;
    std::shared_ptr<SinkSwap> swap;  // when set, no frame
  };

  std::unique_ptr<FrameSource> source_;
  // The camera images' memory, back from the sinks for the source to fill again.
  std::shared_ptr<FramePool> frame_pool_ = std::make_shared<FramePool>();
  size_t held_frames_bound_ = 0;  // frames the stages with latency hold back, as started
  StageFactory stage_factory_;
  SinkFactory sink_factory_;
  std::vector<SinkSlot> sink_slots_;
  std::vector<std::unique_ptr<Stage>> stages_;
  std::vector<std::shared_ptr<const StageAssets>> running_assets_;  // what config_ was loaded into, per stage
  std::vector<std::unique_ptr<FrameSink>> unkeyed_sinks_;  // given to the constructor, until start()
  // Each running sink on its own thread; the list is changed by the sink thread (reloads) under
  // sinks_mutex_, which status() takes to read it.
  std::vector<std::unique_ptr<SinkWorker>> sinks_;
  mutable std::mutex sinks_mutex_;
  Config config_;
  std::atomic<int64_t> max_frames_{0};  // config_.pipeline.max_frames, for the capture thread
  std::unique_ptr<BoundedQueue<FrameContext>> to_process_;
  std::unique_ptr<BoundedQueue<ToSink>> to_sink_;
  std::optional<StereoPacker> stereo_packer_;  // a stereo panorama packed for the sinks (sink thread only)
  std::thread capture_thread_, processing_thread_, sink_thread_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> finished_{false};
  std::atomic<int64_t> busy_since_ns_{0};       // 0 while the processing thread waits for a frame
  std::atomic<int64_t> sink_busy_since_ns_{0};  // 0 while the sink thread waits for a frame

  // Between frames, on the processing thread: swaps in the loaded reload it claimed.
  void apply_reconfigure(const std::shared_ptr<StageReloader::Request>& request);
  std::shared_ptr<StageReloader> reloader_;  // made by start() with the stages' loaders
  int64_t start_ns_ = 0;

  mutable std::mutex metrics_mutex_;
  PipelineMetrics metrics_;
};

}  // namespace arpipe
