// Exact frame times (see frame_times.h).
#include "core/pipeline/frame_times.h"

#include <cmath>

namespace arpipe {
namespace {

__extension__ typedef __int128 Int128;  // k * 1e9 * 1001 overflows int64 after ~9e6 frames

// fps as the exact fraction numerator / denominator when it is one of the usual rates (integral,
// or NTSC's n * 1000 / 1001); 0 / 0 otherwise.
struct ExactRate {
  int64_t numerator = 0;
  int64_t denominator = 0;
};
ExactRate exact_rate(double fps) {
  for (const int64_t denominator : {int64_t(1), int64_t(1001)}) {
    const double scaled = fps * double(denominator);
    const double nearest = std::round(scaled);
    if (nearest >= 1 && nearest < 1e12 && std::abs(scaled - nearest) <= 1e-9 * nearest)
      return {int64_t(nearest), denominator};
  }
  return {};
}

}  // namespace

int64_t frames_to_ns(int64_t frames, int64_t rate_num, int64_t rate_den) {
  // round(a / b) = floor((2a + b) / 2b) for a >= 0, b > 0.
  const Int128 a = Int128(frames) * 1'000'000'000 * rate_den;
  const Int128 b = rate_num;
  return int64_t((2 * a + b) / (2 * b));
}

int64_t frame_offset_ns(double fps, uint64_t k) {
  const ExactRate rate = exact_rate(fps);
  if (rate.numerator > 0) return frames_to_ns(int64_t(k), rate.numerator, rate.denominator);
  return std::llround(double(k) * 1e9 / fps);
}

}  // namespace arpipe
