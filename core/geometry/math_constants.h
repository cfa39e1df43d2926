// Constants that several source files use, defined once: in a unity build (ARPIPE_UNITY_BUILD)
// files share a translation unit, where one file's private copy would collide with another's.
// Include from .cpp files only.
#pragma once

#include <limits>
#include <numbers>

namespace arpipe {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTwoPi = 2 * std::numbers::pi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace arpipe
