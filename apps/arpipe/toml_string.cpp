// toml_string: quoting a value for the config overrides the commands build.
#include <string>

#include "apps/arpipe/commands.h"

namespace arpipe {

// Control characters are escaped (\n, \uXXXX), so a path with a newline stays one TOML value on
// one line: the config refuses an override with a raw newline.
std::string toml_string(const std::string& text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out = "\"";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (byte < 0x20 || byte == 0x7f) {
      out += "\\u00";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xf];
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace arpipe
