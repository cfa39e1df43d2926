// Paces a source's frames in real time against the steady clock (source.pacing = "timestamps"):
// the replay and the panorama source wait here for each frame's due time, and interrupt() from
// another thread ends a wait at once.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace arpipe {

class PacingClock {
 public:
  // Waits until due_ns after the start, the start being such that the first call's due time is
  // now. False when interrupt() ended the wait (the interrupt is then used up).
  bool wait(int64_t due_ns) {
    std::unique_lock lock(mutex_);
    if (!started_) {
      started_ = true;
      start_ = std::chrono::steady_clock::now() - std::chrono::nanoseconds(due_ns);
    }
    wake_.wait_until(lock, start_ + std::chrono::nanoseconds(due_ns), [&] { return interrupted_; });
    const bool interrupted = interrupted_;
    interrupted_ = false;
    return !interrupted;
  }

  void interrupt() {
    {
      std::lock_guard lock(mutex_);
      interrupted_ = true;
    }
    wake_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool started_ = false;
  std::chrono::steady_clock::time_point start_;
  bool interrupted_ = false;
};

}  // namespace arpipe
