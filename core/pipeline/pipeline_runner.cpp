#include "core/pipeline/pipeline_runner.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <exception>
#include <future>
#include <optional>

#include "core/log.h"
#include "core/pipeline/helper_thread.h"
#include "core/pipeline/monotonic_clock.h"
#include "core/system/thread_cpu.h"

namespace arpipe {

PipelineRunner::PipelineRunner(std::unique_ptr<FrameSource> source, StageFactory stages,
                               std::vector<std::unique_ptr<FrameSink>> sinks, const Config& config)
    : source_(std::move(source)), stage_factory_(std::move(stages)), config_(config),
      max_frames_(config.pipeline.max_frames) {
  unkeyed_sinks_ = std::move(sinks);
  const PanoramaConfig& panorama = config.source.panorama;
  if (config.source.type == SourceType::Panorama && panorama.layout != PanoramaLayout::Equirect &&
      panorama.view.stereo_output != StereoOutput::Frames)  // (mono frames pass through it)
    stereo_packer_.emplace(panorama.view.stereo_output);
}

PipelineRunner::~PipelineRunner() {
  stop();
  wait();
  // The sinks go first, while the queues and the source they may still ask about (a live output's
  // status() from its connection threads) exist.
  std::vector<std::unique_ptr<SinkWorker>> sinks;
  {
    std::lock_guard lock(sinks_mutex_);
    sinks.swap(sinks_);
  }
  sinks.clear();
}

void PipelineRunner::start() {
  const size_t depth = size_t(config_.pipeline.queue_depth);
  // Replay must be deterministic frame for frame, so it blocks; a live camera must not fall behind.
  // A frame a live camera's queue drops gives its memory back to the source, like one the sinks are done with.
  to_process_ = std::make_unique<BoundedQueue<FrameContext>>(
      depth, source_->is_live() ? OverflowPolicy::DropOldest : OverflowPolicy::Block,
      [pool = frame_pool_](FrameContext&& dropped) { pool->give(std::move(dropped.camera.data)); });
  to_sink_ = std::make_unique<BoundedQueue<ToSink>>(depth, OverflowPolicy::Block);
  start_ns_ = monotonic_now_ns();

  // The stages are created and configured on the processing thread, which owns their GL context.
  std::promise<void> configured;
  auto configured_future = configured.get_future();
  processing_thread_ = std::thread([this, &configured] {
    name_this_thread("arp-process");
    try {
      stages_ = stage_factory_();
      std::vector<std::pair<std::string, StageAssetLoader>> loaders;
      for (auto& stage : stages_) {
        StageAssetLoader loader = stage->asset_loader();
        running_assets_.push_back(loader ? loader(config_) : nullptr);
        stage->configure_loaded(config_, running_assets_.back());
        loaders.emplace_back(std::string(stage->name()), std::move(loader));
      }
      for (auto& stage : stages_) stage->prepare(source_->camera_model());
      reloader_ = std::make_shared<StageReloader>(std::move(loaders), sink_slots_, config_);
    } catch (...) {
      stages_.clear();
      running_assets_.clear();
      configured.set_exception(std::current_exception());
      return;
    }
    configured.set_value();
    processing_loop();
  });
  try {
    configured_future.get();
  } catch (...) {
    processing_thread_.join();
    throw;
  }
  // The outputs are opened last, once nothing slow or refusable is left before the first frame.
  std::vector<std::unique_ptr<SinkWorker>> workers;
  try {
    for (auto& sink : unkeyed_sinks_) workers.push_back(make_worker(std::string(), std::move(sink)));
    unkeyed_sinks_.clear();
    if (sink_factory_)
      for (auto& sink : sink_factory_()) workers.push_back(make_worker(std::string(), std::move(sink)));
    for (const SinkSlot& slot : sink_slots_)
      if (std::unique_ptr<FrameSink> sink = slot.make(config_)) workers.push_back(make_worker(slot.key, std::move(sink)));
  } catch (...) {
    to_process_->close();  // the processing thread ends, destroying the stages on its own thread
    processing_thread_.join();
    throw;
  }
  for (const auto& stage : stages_) held_frames_bound_ += size_t(std::max(0, stage->latency_frames()));
  frame_pool_->keep_at_most(frames_in_flight_bound(workers.size()));
  {
    std::lock_guard lock(sinks_mutex_);
    sinks_ = std::move(workers);
  }
  sink_thread_ = std::thread([this] {
    name_this_thread("arp-sinks");
    sink_loop();
  });
  capture_thread_ = std::thread([this] {
    name_this_thread("arp-capture");
    capture_loop();
  });
}

void PipelineRunner::stop() {
  stop_requested_ = true;
  if (source_) source_->interrupt();
}

void PipelineRunner::wait() {
  if (capture_thread_.joinable()) capture_thread_.join();
  if (processing_thread_.joinable()) processing_thread_.join();
  if (sink_thread_.joinable()) sink_thread_.join();
}

void PipelineRunner::capture_loop() {
  std::optional<uint64_t> previous_sequence;
  uint64_t index = 0;
  while (!stop_requested_) {
    const int64_t max_frames = max_frames_.load();
    if (max_frames > 0 && int64_t(index) >= max_frames) break;
    FrameContext ctx;
    ctx.camera.data = frame_pool_->take();  // a source that copies into it allocates nothing
    SourceStatus status = SourceStatus::EndOfStream;
    try {
      status = source_->next(ctx.camera);
    } catch (const std::exception& e) {  // sources must not throw; survive one that does
      log::error("source {}: {}", source_->describe(), e.what());
      status = SourceStatus::Retry;
    }
    if (status == SourceStatus::EndOfStream) break;
    if (status == SourceStatus::Retry) {
      std::lock_guard lock(metrics_mutex_);
      ++metrics_.source_retries;
      continue;
    }
    const uint64_t sequence = ctx.camera.meta.sequence;
    if (previous_sequence && sequence > *previous_sequence + 1) ctx.dropped_before = sequence - *previous_sequence - 1;
    previous_sequence = sequence;
    ctx.arrived_ns = monotonic_now_ns();
    ctx.camera_model = source_->camera_model();
    ctx.input_index = index++;
    {
      std::lock_guard lock(metrics_mutex_);
      ++metrics_.frames_in;
      metrics_.sequence_gaps += ctx.dropped_before;
    }
    if (!to_process_->push(std::move(ctx))) break;
  }
  to_process_->close();
}

size_t PipelineRunner::frames_in_flight_bound(size_t sink_count) const {
  const auto depth = size_t(config_.pipeline.queue_depth);
  // One in each of the capture and sink threads and the stereo packer, two in the processing
  // thread (with the overlap, the frame waiting for the next one and the next one, tracked on the
  // helper); the two queues between them; the sinks' queues hold the newest frames (shared), each
  // sink one it is consuming and one it may keep (a preview's latest frame).
  return 5 + 2 * depth + held_frames_bound_ + size_t(config_.pipeline.sink_queue_depth) + 2 * sink_count;
}

size_t PipelineRunner::first_stage_with_latency() const {
  for (size_t i = 0; i < stages_.size(); ++i)
    if (stages_[i]->latency_frames() > 0) return i;
  return stages_.size();
}

void PipelineRunner::finish_frame(FrameContext& ctx, size_t first_stage) {
  if (busy_since_ns_ == 0) busy_since_ns_ = monotonic_now_ns();  // a held frame at the end of the stream
  for (size_t i = first_stage; i < stages_.size(); ++i) stages_[i]->process(ctx);
  {
    std::lock_guard lock(metrics_mutex_);
    count_frame(metrics_, ctx);
  }
  // Not busy once the stages are done: a push that waits for a slow sink is the sink's stall, and
  // the sink may take the frame before this thread runs again.
  busy_since_ns_ = 0;
  to_sink_->push(ToSink{std::move(ctx), nullptr});
}

void PipelineRunner::processing_loop() {
  uint64_t expected_index = 0;
  // Frames held back for a stage with latency_frames() > 0 (the motion stage with
  // motion.latency_frames = 1), each with the first stage it has still to go through.
  std::deque<std::pair<FrameContext, size_t>> held;
  const auto finish_held = [&](size_t keep) {
    for (; held.size() > keep; held.pop_front()) finish_frame(held.front().first, held.front().second);
  };
  // A frame's stages from `first` on: those before the one with latency, then held or finished.
  const auto run_from = [&](FrameContext& ctx, size_t first) {
    const size_t split = first_stage_with_latency();
    for (size_t i = first; i < split; ++i) stages_[i]->process(ctx);
    if (split < stages_.size()) {
      stages_[split]->look_ahead(ctx);
      held.emplace_back(std::move(ctx), split);
      finish_held(size_t(stages_[split]->latency_frames()));
    } else {
      finish_held(0);  // held under a config that has since dropped the latency
      finish_frame(ctx, split);
    }
  };
  // What the later stages do ahead on a frame (Stage::process_ahead), once, by whichever thread
  // comes to it first: the helper after the frame's first stage, or this thread after the frame
  // before (a still frame's tracking is quick, its drawing quicker: either may finish first).
  const auto later_stages_ahead = [&](FrameContext& ctx, std::atomic<bool>& taken) {
    if (taken.exchange(true)) return;
    for (size_t i = 1; i < stages_.size(); ++i) stages_[i]->process_ahead(ctx);
  };
  // Whether the first stage may run on its own, ahead of the others (see below).
  const auto first_runs_ahead = [&] {
    return config_.pipeline.overlap_first_stage && !stages_.empty() && stages_[0]->can_run_ahead() &&
           first_stage_with_latency() > 0;
  };
  // A frame whose first stage has run and whose later stages wait for the next frame: when the
  // next one is already queued (a replay, a camera the pipeline lags behind), its first stage
  // (tracking) runs on a helper thread while this thread runs the later stages (rendering) of this
  // one. Each stage still sees the frames in order. A frame with nothing queued behind it goes on
  // at once, so a live camera's frames wait for no later frame.
  std::optional<FrameContext> waiting;
  std::optional<HelperThread> helper;  // started at the first overlap
  while (auto ctx = to_process_->pop()) {
    busy_since_ns_ = monotonic_now_ns();
    // Frames the live queue dropped are lost just like a sequence gap, so the next frame says so.
    ctx->dropped_before += ctx->input_index - expected_index;
    expected_index = ctx->input_index + 1;
    if (std::shared_ptr<StageReloader::Request> request = reloader_->claim()) {
      // The waiting frame finishes under the config its first stage ran with.
      if (waiting) run_from(*waiting, 1);
      waiting.reset();
      apply_reconfigure(request);
    }
    if (waiting) {
      FrameContext& next = *ctx;
      if (!helper) helper.emplace();
      std::atomic<bool> ahead_taken{false};
      helper->start([&] {
        stages_[0]->process(next);
        later_stages_ahead(next, ahead_taken);
      });
      run_from(*waiting, 1);
      later_stages_ahead(next, ahead_taken);
      helper->wait();
      waiting.reset();
      {
        std::lock_guard lock(metrics_mutex_);
        ++metrics_.frames_overlapped;
      }
      if (to_process_->size() > 0) waiting = std::move(*ctx);
      else run_from(*ctx, 1);
    } else if (first_runs_ahead() && to_process_->size() > 0) {
      stages_[0]->process(*ctx);
      waiting = std::move(*ctx);
    } else {
      run_from(*ctx, 0);
    }
    busy_since_ns_ = 0;
  }
  if (waiting) run_from(*waiting, 1);
  finish_held(0);  // the end of the stream: the last frames go on without a look-ahead
  to_sink_->close();
  reloader_->close("the stream has ended; nothing left to reconfigure");
  stages_.clear();  // destroys the GL context on the thread that made it
  running_assets_.clear();
}

std::unique_ptr<SinkWorker> PipelineRunner::make_worker(std::string key, std::unique_ptr<FrameSink> sink) const {
  // Replay must lose nothing, so a full queue waits for its sink; a live camera must not fall
  // behind, so a slow sink loses its oldest frame (and counts it), never the others'.
  return std::make_unique<SinkWorker>(std::move(key), std::move(sink), size_t(config_.pipeline.sink_queue_depth),
                                      source_->is_live() ? OverflowPolicy::DropOldest : OverflowPolicy::Block);
}

namespace {

// A live run's sink that fell behind lost its oldest frames; the last word on it says how many,
// so that its output can be reconciled with the frames out.
void log_sink_drops(const SinkWorker& worker) {
  const SinkStats stats = worker.stats();
  if (stats.dropped > 0)
    log::warn("{}: took {} frames, dropped {} it fell behind on", stats.key, stats.consumed, stats.dropped);
}

}  // namespace

void PipelineRunner::sink_loop() {
  // Each sink's thread tells it the run is up before its first frame: the stages are configured
  // and every sink exists, so the outputs of an earlier run may now be replaced.
  for (auto& worker : sinks_) worker->start();
  while (auto item = to_sink_->pop()) {
    sink_busy_since_ns_ = monotonic_now_ns();
    if (item->swap) {
      swap_sinks(*item->swap);
      sink_busy_since_ns_ = 0;
      continue;
    }
    if (stereo_packer_) {  // a stereo panorama's eyes go on as one frame
      std::optional<FrameContext> pair = stereo_packer_->add(std::move(item->frame));
      if (!pair) {
        sink_busy_since_ns_ = 0;
        continue;
      }
      item->frame = std::move(*pair);
    }
    const int64_t origin_ns = item->frame.latency_origin_ns();
    // When the last sink lets go of the frame, its camera image's memory goes back to the source.
    auto frame = std::shared_ptr<const FrameContext>(
        new FrameContext(std::move(item->frame)), [pool = frame_pool_](FrameContext* done) {
          pool->give(std::move(done->camera.data));
          delete done;
        });
    for (auto& worker : sinks_) worker->push(frame);
    const int64_t now = monotonic_now_ns();
    sink_busy_since_ns_ = 0;
    std::lock_guard lock(metrics_mutex_);
    ++metrics_.frames_out;
    metrics_.latency_seconds.add(double(now - origin_ns) * 1e-9);
    metrics_.wall_seconds = double(now - start_ns_) * 1e-9;
  }
  if (stereo_packer_ && stereo_packer_->unpaired() > 0)
    log::warn("stereo output: {} eye frames came without their other eye and were not shown", stereo_packer_->unpaired());
  // Every sink takes what is queued for it and flushes.
  for (auto& worker : sinks_) {
    worker->finish();
    log_sink_drops(*worker);
  }
  finished_ = true;
}

void PipelineRunner::swap_sinks(SinkSwap& swap) {
  for (auto& [key, next] : swap.sinks) {
    std::unique_ptr<SinkWorker> running;
    {
      std::lock_guard lock(sinks_mutex_);
      auto found = std::find_if(sinks_.begin(), sinks_.end(), [&](const auto& w) { return w->key() == key; });
      if (found != sinks_.end()) {
        running = std::move(*found);
        sinks_.erase(found);
      }
    }
    if (running) {
      // Everything it was handed is written and durable, and its output closed, before a new
      // sink may take over the same path.
      running->finish();
      log_sink_drops(*running);
      const std::string closed = running->describe();
      running.reset();
      log::info("{}: closed {}", key, closed);
    }
    if (next) {
      std::unique_ptr<SinkWorker> worker = make_worker(key, std::move(next));
      worker->start();
      log::info("{}: started {}", key, worker->describe());
      std::lock_guard lock(sinks_mutex_);
      sinks_.push_back(std::move(worker));
    }
  }
  std::lock_guard lock(sinks_mutex_);
  frame_pool_->keep_at_most(frames_in_flight_bound(sinks_.size()));
}

bool PipelineRunner::reconfigure(const Config& config, std::string& error,
                                 std::chrono::milliseconds boundary_timeout) {
  if (!reloader_) {
    error = "the pipeline has not started";
    return false;
  }
  return reloader_->reconfigure(reloader_->new_ticket(), config, error, boundary_timeout);
}

void PipelineRunner::apply_reconfigure(const std::shared_ptr<StageReloader::Request>& request) {
  const StageReloader::Loaded& next = reloader_->loaded(*request);
  std::string error;
  for (size_t i = 0; i < stages_.size(); ++i) {
    try {
      stages_[i]->configure_loaded(next.config, next.assets[i]);
    } catch (const std::exception& e) {
      error = fmt::format("stage {}: {}", stages_[i]->name(), e.what());
      break;
    }
  }
  if (!error.empty()) {
    // Put every stage back on the configuration that was running, with the assets it was loaded into.
    for (size_t i = 0; i < stages_.size(); ++i) {
      try {
        stages_[i]->configure_loaded(config_, running_assets_[i]);
      } catch (const std::exception& e) {
        log::error("stage {} could not return to the running config: {}", stages_[i]->name(), e.what());
      }
    }
  } else {
    config_ = next.config;
    running_assets_ = next.assets;
    max_frames_ = config_.pipeline.max_frames;
    // The frames before this one go to the sinks that were running; from this one on, the new ones.
    if (next.sinks) to_sink_->push(ToSink{FrameContext(), next.sinks});
  }
  for (auto& stage : stages_) stage->prepare(source_->camera_model());
  reloader_->finish(request, error);
}

PipelineMetrics PipelineRunner::metrics() const {
  std::lock_guard lock(metrics_mutex_);
  PipelineMetrics m = metrics_;
  if (to_process_) m.queue_drops = to_process_->dropped();
  return m;
}

PipelineStatus PipelineRunner::status() const {
  PipelineStatus status;
  status.metrics = metrics();
  {
    std::lock_guard lock(sinks_mutex_);
    for (const auto& worker : sinks_) status.sinks.push_back(worker->stats());
  }
  status.source = source_->describe();
  status.source_health = source_->health();
  status.capture = source_->capture_counts();
  status.live = source_->is_live();
  status.source_connected = source_->connected();
  status.uptime_seconds = start_ns_ ? double(monotonic_now_ns() - start_ns_) * 1e-9 : 0;
  return status;
}

bool PipelineRunner::healthy(int64_t max_stall_ns) const {
  const int64_t now = monotonic_now_ns();
  const auto stalled = [&](int64_t since) { return since != 0 && now - since >= max_stall_ns; };
  if (stalled(busy_since_ns_) || stalled(sink_busy_since_ns_)) return false;
  std::lock_guard lock(sinks_mutex_);
  for (const auto& worker : sinks_)
    if (stalled(worker->busy_since_ns())) return false;
  return true;
}

}  // namespace arpipe
