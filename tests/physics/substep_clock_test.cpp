// The substep grid is exact in integers however long the run: substep k is t0 + floor(k 1e9 / hz),
// also for rates that do not divide a second, and across the once-a-second origin moves.
#include "core/physics/substep_clock.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arpipe {
namespace {

TEST(SubstepClock, EverySubstepIsOnTheIntegerGrid) {
  for (int hz : {960, 480, 1000, 7, 999}) {
    const int64_t t0 = 123'456'789'012'345;
    SubstepClock clock(hz);
    clock.restart(t0);
    for (int64_t k = 0; k < 20 * hz + 3; ++k) {
      // Independently: k * 1e9 < 2^64 is exact in a long double, and the quotient's fraction is at
      // most 1 - 1 / hz, far from rounding up to the next integer.
      const auto offset = static_cast<int64_t>(std::floor(static_cast<long double>(k) * 1e9L / hz));
      ASSERT_EQ(clock.now_ns(), t0 + offset) << "hz " << hz << ", k " << k;
      ASSERT_GT(clock.next_ns(), clock.now_ns());
      clock.tick();
    }
  }
}

TEST(SubstepClock, ARestartBeginsANewGrid) {
  SubstepClock clock(960);
  clock.restart(0);
  for (int i = 0; i < 5; ++i) clock.tick();
  clock.restart(3'600'000'000'000);
  EXPECT_EQ(clock.now_ns(), 3'600'000'000'000);
  EXPECT_EQ(clock.next_ns(), 3'600'000'000'000 + 1'000'000'000 / 960);
}

}  // namespace
}  // namespace arpipe
