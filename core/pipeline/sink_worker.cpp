#include "core/pipeline/sink_worker.h"

#include "core/pipeline/monotonic_clock.h"
#include "core/system/thread_cpu.h"

namespace arpipe {

SinkWorker::SinkWorker(std::string key, std::unique_ptr<FrameSink> sink, size_t queue_depth, OverflowPolicy policy)
    : key_(std::move(key)), sink_(std::move(sink)), description_(sink_->describe()), queue_(queue_depth, policy) {}

SinkWorker::~SinkWorker() { finish(); }

void SinkWorker::start() {
  thread_ = std::thread([this] {
    // "arp-sink png" for sinks.png: Linux keeps 15 bytes of a name.
    name_this_thread("arp-sink " + (key_.starts_with("sinks.") ? key_.substr(6) : key_));
    run();
  });
}

void SinkWorker::push(std::shared_ptr<const FrameContext> frame) { queue_.push(std::move(frame)); }

void SinkWorker::finish() {
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void SinkWorker::run() {
  sink_->run_started();
  while (auto frame = queue_.pop()) {
    busy_since_ns_ = monotonic_now_ns();
    sink_->consume_shared(*frame);
    busy_since_ns_ = 0;
    ++consumed_;
  }
  busy_since_ns_ = monotonic_now_ns();
  sink_->flush();
  busy_since_ns_ = 0;
}

SinkStats SinkWorker::stats() const {
  return SinkStats{key_.empty() ? description_ : key_, consumed_.load(), queue_.dropped(), queue_.size()};
}

}  // namespace arpipe
