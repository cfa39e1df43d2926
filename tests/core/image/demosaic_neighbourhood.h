// The demosaic error bound's neighbourhood (tests/core/image/bayer_test.cpp explains the bound):
// the range of the true linear values over a pixel's (2r+1)^2 neighbourhood and all three channels,
// and whether that neighbourhood is flat (every pixel within `flat_tolerance` of this one, per channel).
#pragma once

#include <algorithm>
#include <cmath>

namespace arpipe::test {

struct Neighbourhood {
  double lo = 1e300;
  double hi = -1e300;
  bool flat = true;
};

// truth(x, y, c): the true linear value of channel c at (x, y) in a w x h image.
template <class Truth>
Neighbourhood demosaic_neighbourhood(const Truth& truth, int x, int y, int w, int h, int radius, double flat_tolerance) {
  Neighbourhood n;
  for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v)
    for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u)
      for (int c = 0; c < 3; ++c) {
        const double t = truth(u, v, c);
        n.lo = std::min(n.lo, t);
        n.hi = std::max(n.hi, t);
        n.flat = n.flat && std::abs(t - truth(x, y, c)) <= flat_tolerance;
      }
  return n;
}

}  // namespace arpipe::test
