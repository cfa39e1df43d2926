// CLOCK_MONOTONIC in int64 nanoseconds, the one time base of the project (docs/DESIGN.md "Time"),
// and the millisecond stopwatch the stages time themselves with.
#pragma once

#include <chrono>
#include <cstdint>
#include <ctime>

namespace arpipe {

inline int64_t monotonic_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Milliseconds since start, for FrameContext::record_timing.
inline double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace arpipe
