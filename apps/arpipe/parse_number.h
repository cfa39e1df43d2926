// A command-line number: the whole text must be a finite number (std::from_chars), or nothing.
#pragma once

#include <optional>
#include <string>

namespace arpipe {

std::optional<double> parse_number(const std::string& text);

}  // namespace arpipe
