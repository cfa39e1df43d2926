// A histogram of durations in seconds with fixed buckets, as Prometheus exposes one (cumulative
// counts per upper bound, a sum and a count): stage times and end-to-end latency.
#pragma once

#include <array>
#include <cstdint>

namespace arpipe {

class LatencyHistogram {
 public:
  // Upper bounds in seconds: 0.5 ms to 5 s, about three per decade, covering a stage's time on a
  // fast board up to a client that is seconds behind.
  static constexpr std::array<double, 14> kBounds{0.0005, 0.001, 0.002, 0.005, 0.01, 0.02, 0.033,
                                                  0.05,   0.1,   0.2,   0.5,   1.0,  2.0,  5.0};

  void add(double seconds) {
    if (!(seconds >= 0)) seconds = 0;  // NaN and clock steps count as zero, not as a gap
    size_t i = 0;
    while (i < kBounds.size() && seconds > kBounds[i]) ++i;
    ++counts_[i];
    ++count_;
    sum_ += seconds;
  }
  // Observations at most kBounds[i] (i < kBounds.size()), or all of them (i == kBounds.size(): +Inf).
  uint64_t cumulative(size_t i) const {
    uint64_t total = 0;
    for (size_t k = 0; k <= i && k < counts_.size(); ++k) total += counts_[k];
    return total;
  }
  uint64_t count() const { return count_; }
  double sum() const { return sum_; }

 private:
  std::array<uint64_t, kBounds.size() + 1> counts_{};  // the last: above every bound
  uint64_t count_ = 0;
  double sum_ = 0;
};

}  // namespace arpipe
