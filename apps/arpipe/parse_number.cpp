// A command-line number (see parse_number.h).
#include "apps/arpipe/parse_number.h"

#include <charconv>
#include <cmath>

namespace arpipe {

std::optional<double> parse_number(const std::string& text) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace arpipe
