// The simulator's random numbers: PCG32 (O'Neill), seeded per (seed, stream) so that every pixel of
// every frame draws its own reproducible sequence whatever thread renders it.
#pragma once

#include <cstdint>

namespace arpipe::sim {

class SampleRng {
 public:
  SampleRng(uint64_t seed, uint64_t stream) : increment_((stream << 1u) | 1u) {
    next_u32();
    state_ += mix(seed);
    next_u32();
  }

  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + increment_;
    const auto xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const auto rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1), 32 bits of resolution.
  double uniform() { return next_u32() * (1.0 / 4294967296.0); }

 private:
  // splitmix64 finaliser: nearby seeds give unrelated sequences.
  static uint64_t mix(uint64_t x) {
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30u)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27u)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31u);
  }

  uint64_t state_ = 0;
  uint64_t increment_;
};

}  // namespace arpipe::sim
