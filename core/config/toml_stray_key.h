// Finding the key a TOML table should not have: the first one in file order that is not in the
// allowed list, with where it is, so every loader (config, scenes, boards) reports the same one.
#pragma once

#include <toml++/toml.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arpipe {

struct StrayKey {
  std::string name;
  toml::source_region where;  // the key's own place, or its value's when the key has none
};

std::optional<StrayKey> first_stray_key(const toml::table& table, const std::vector<std::string_view>& allowed);

}  // namespace arpipe
