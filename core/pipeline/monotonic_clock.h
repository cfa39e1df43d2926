// CLOCK_MONOTONIC in int64 nanoseconds, the one time base of the project (DESIGN.md "Time").
#pragma once

#include <cstdint>
#include <ctime>

namespace arpipe {

inline int64_t monotonic_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace arpipe
