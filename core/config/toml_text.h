// Writing values as TOML text and as message text: shared by the TOML section reader (messages),
// the config's defaults writer and the overrides.
#pragma once

#include <string>
#include <string_view>

namespace arpipe {

// A TOML basic string ("a\"b"); control characters are escaped, so the text stays on one line.
std::string toml_quoted(std::string_view text);

// A float as TOML writes it: always with a point or an exponent (7 -> "7.0", 1e-9 -> "1e-09").
std::string toml_float(double value);

// Text for a message: control characters shown as escapes, so a value cannot start a new line.
std::string printable(std::string_view text);

// The text without leading and trailing white space.
std::string_view trim_space(std::string_view text);
// A range bound for messages and help text: 4 -> "4", 0.95 -> "0.95", 1e12 -> "1e12".
std::string bound_text(double value);

}  // namespace arpipe
