// A command-line value of N comma-separated finite numbers ("0.5,-0.5,1.6"), as options such as
// `arpipe proxy simplify --pose` and `arpipe bench hybrid --viewpoint` take them.
#pragma once

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string_view>
#include <system_error>

namespace arpipe::cli {

// Exactly N numbers, each finite, nothing else between the commas; nullopt otherwise.
template <size_t N>
std::optional<std::array<double, N>> parse_number_list(std::string_view text) {
  std::array<double, N> v{};
  size_t start = 0;
  for (size_t i = 0; i < N; ++i) {
    const size_t comma = text.find(',', start);
    if ((i + 1 < N) != (comma != std::string_view::npos)) return std::nullopt;
    const std::string_view field = text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v[i]);
    if (ec != std::errc() || end != field.data() + field.size() || !std::isfinite(v[i])) return std::nullopt;
    start = comma + 1;
  }
  return v;
}

}  // namespace arpipe::cli
