// One sink on its own thread behind its own bounded queue, so that a slow sink (a stalled disk, a
// busy encoder) never delays the pipeline or another sink: a live source drops the sink's oldest
// queued frame and counts it, a replay blocks so that nothing is lost.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "core/pipeline/bounded_queue.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/pipeline_status.h"

namespace arpipe {

class SinkWorker {
 public:
  // key: the sink's config key, or empty for a sink no reload replaces.
  SinkWorker(std::string key, std::unique_ptr<FrameSink> sink, size_t queue_depth, OverflowPolicy policy);
  ~SinkWorker();  // finish()
  SinkWorker(const SinkWorker&) = delete;
  SinkWorker& operator=(const SinkWorker&) = delete;

  // Starts the thread, which tells the sink the run is up before its first frame.
  void start();
  // Queues a frame (blocks while the queue is full under OverflowPolicy::Block).
  void push(std::shared_ptr<const FrameContext> frame);
  // No more frames: the sink takes what is queued, flushes, and the thread ends. Idempotent.
  void finish();

  const std::string& key() const { return key_; }
  const std::string& describe() const { return description_; }
  SinkStats stats() const;
  // CLOCK_MONOTONIC since when the sink has been inside one frame (or its flush); 0 while it waits.
  int64_t busy_since_ns() const { return busy_since_ns_; }

 private:
  void run();

  std::string key_;
  std::unique_ptr<FrameSink> sink_;
  std::string description_;  // made once: stats() is read from other threads
  BoundedQueue<std::shared_ptr<const FrameContext>> queue_;
  std::thread thread_;
  std::atomic<uint64_t> consumed_{0};
  std::atomic<int64_t> busy_since_ns_{0};
};

}  // namespace arpipe
