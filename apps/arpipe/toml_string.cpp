// toml_string: quoting a value for the config overrides the commands build.
#include <string>

#include "apps/arpipe/commands.h"

namespace arpipe {

std::string toml_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace arpipe
