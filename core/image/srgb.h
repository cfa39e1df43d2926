// The IEC 61966-2-1 sRGB transfer function and its inverse, on values in [0, 1]: the curve the
// simulator's sensor writes and that most cameras' ISPs approximate.
#pragma once

#include <algorithm>
#include <cmath>

namespace arpipe {

// Linear light to the encoded value. Full scale maps to exactly 1 (1.055 - 0.055 is 1 - 1 ulp in
// binary, hence the clamp).
inline double srgb_encode(double linear) {
  if (linear <= 0.0031308) return 12.92 * linear;
  if (linear >= 1) return 1;
  return std::min(1.0, 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055);
}

// The encoded value to linear light.
inline double srgb_decode(double encoded) {
  if (encoded <= 0.04045) return encoded / 12.92;
  if (encoded >= 1) return 1;
  return std::min(1.0, std::pow((encoded + 0.055) / 1.055, 2.4));
}

}  // namespace arpipe
