// The ranges a number or an integer read from a file must lie in, with the words that say them
// in messages ("expected a number in [1, 4]") and in `arpipe config --defaults` ("[1, 4]: ...").
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

namespace arpipe {

// A check on a finite number, with the words that describe it ("[1, 4]", ">= 0").
struct NumberRange {
  std::function<bool(double)> ok;  // empty: every finite number
  std::string interval;            // "[1, 4]"; empty for every number
  std::string unit;                // "m", "degrees": shown in messages as " (m)"

  static NumberRange any() { return {}; }
  static NumberRange closed(double lo, double hi);      // [lo, hi]
  static NumberRange open_closed(double lo, double hi);  // (lo, hi]
  static NumberRange closed_open(double lo, double hi);  // [lo, hi)
  static NumberRange at_least(double lo);                // >= lo
  static NumberRange above(double lo);                   // > lo
  // A rule of its own: interval is how messages and help texts say it.
  static NumberRange rule(std::function<bool(double)> ok, std::string interval) { return {std::move(ok), std::move(interval), {}}; }
  NumberRange in(std::string unit_name) const { NumberRange r = *this; r.unit = std::move(unit_name); return r; }

  // "a number in [1, 4] (m)"
  std::string phrase() const;
};

// Integer bounds, inclusive.
struct IntRange {
  int64_t min = std::numeric_limits<int64_t>::min();
  int64_t max = std::numeric_limits<int64_t>::max();
  // "[0, 30]", ">= 1", "" for any
  std::string interval() const;
  std::string phrase() const;  // "an integer in [0, 30]"
};

}  // namespace arpipe
