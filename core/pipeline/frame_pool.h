// Pixel memory that the pipeline hands back to the source: when the last sink is done with a
// frame, its camera image's bytes (capacity kept) wait here for the capture thread, which gives
// them to the source to fill again. A source that copies into the Frame it is given (the V4L2
// source) then allocates nothing per frame in steady state, as long as `keep` is at least the frames
// the pipeline can hold at once (PipelineRunner sets it from its queues). Thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace arpipe {

class FramePool {
 public:
  explicit FramePool(size_t keep = 8) : keep_(keep) {}

  // How many to keep from now on (those kept beyond it are freed).
  void keep_at_most(size_t keep) {
    std::lock_guard lock(mutex_);
    keep_ = keep;
    if (kept_.size() > keep_) kept_.resize(keep_);
  }

  // Bytes to fill (their old contents, or empty when none wait).
  std::vector<uint8_t> take() {
    std::lock_guard lock(mutex_);
    if (kept_.empty()) return {};
    std::vector<uint8_t> bytes = std::move(kept_.back());
    kept_.pop_back();
    return bytes;
  }
  void give(std::vector<uint8_t>&& bytes) {
    if (bytes.capacity() == 0) return;
    std::lock_guard lock(mutex_);
    if (kept_.size() < keep_) kept_.push_back(std::move(bytes));
  }

 private:
  size_t keep_;
  std::mutex mutex_;
  std::vector<std::vector<uint8_t>> kept_;
};

}  // namespace arpipe
