// A bounded multi-producer queue between pipeline threads. Two overflow policies:
// Block (replay: deterministic, nothing lost) and DropOldest (live: keep latency low, count drops).
// A dropped item goes to the queue's drop handler when it has one (the pipeline gives a dropped
// frame's memory back to the source), outside the queue's lock.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>

namespace arpipe {

enum class OverflowPolicy { Block, DropOldest };

template <typename T>
class BoundedQueue {
 public:
  using DropHandler = std::function<void(T&&)>;

  BoundedQueue(size_t capacity, OverflowPolicy policy, DropHandler on_drop = {})
      : capacity_(capacity ? capacity : 1), policy_(policy), on_drop_(std::move(on_drop)) {}

  // Returns false when the queue was closed (the item is discarded).
  bool push(T item) {
    std::optional<T> displaced;
    {
      std::unique_lock lock(mutex_);
      if (policy_ == OverflowPolicy::Block) {
        not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
      } else if (items_.size() >= capacity_ && !closed_) {
        displaced.emplace(std::move(items_.front()));
        items_.pop_front();
        ++dropped_;
      }
      if (closed_) return false;
      items_.push_back(std::move(item));
      not_empty_.notify_one();
    }
    if (displaced && on_drop_) on_drop_(std::move(*displaced));
    return true;
  }

  // Blocks until an item arrives; nullopt once the queue is closed and empty.
  std::optional<T> pop() {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  // No more pushes; pop() drains what is left, then returns nullopt.
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  uint64_t dropped() const {
    std::lock_guard lock(mutex_);
    return dropped_;
  }
  size_t size() const {
    std::lock_guard lock(mutex_);
    return items_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<T> items_;
  size_t capacity_;
  OverflowPolicy policy_;
  DropHandler on_drop_;
  bool closed_ = false;
  uint64_t dropped_ = 0;
};

}  // namespace arpipe
