// The fixed substep grid of a physics world: substep k after a (re)start at t0 belongs to
// t0 + floor(k * 1e9 / hz) ns, computed in integers, so every run and every way of chunking the
// advances lands on the same instants.
#pragma once

#include <cstdint>

namespace arpipe {

class SubstepClock {
 public:
  explicit SubstepClock(int hz) : hz_(hz) {}

  void restart(int64_t t_ns) {
    origin_ns_ = t_ns;
    index_ = 0;
  }
  int64_t now_ns() const { return origin_ns_ + offset_ns(index_); }
  int64_t next_ns() const { return origin_ns_ + offset_ns(index_ + 1); }
  // Moves to the next substep. Every hz substeps the origin moves on by exactly one second, so the
  // products stay small however long the run.
  void tick() {
    if (++index_ == hz_) {
      origin_ns_ += kNsPerSecond;
      index_ = 0;
    }
  }
  double step_seconds() const { return 1.0 / hz_; }

 private:
  static constexpr int64_t kNsPerSecond = 1'000'000'000;
  int64_t offset_ns(int64_t k) const { return k * kNsPerSecond / hz_; }

  int hz_;
  int64_t origin_ns_ = 0;
  int64_t index_ = 0;
};

}  // namespace arpipe
