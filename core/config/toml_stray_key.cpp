#include "core/config/toml_stray_key.h"

#include <algorithm>
#include <tuple>

namespace arpipe {

std::optional<StrayKey> first_stray_key(const toml::table& table, const std::vector<std::string_view>& allowed) {
  // toml++ iterates in key order, not file order: look at every key and keep the earliest.
  const toml::key* first = nullptr;
  for (auto&& [k, value] : table) {
    if (std::find(allowed.begin(), allowed.end(), k.str()) != allowed.end()) continue;
    if (first == nullptr || std::tie(k.source().begin.line, k.source().begin.column) <
                                std::tie(first->source().begin.line, first->source().begin.column))
      first = &k;
  }
  if (first == nullptr) return std::nullopt;
  // Keys made by an override (no source line) are placed by their value.
  const toml::source_region& where =
      first->source().begin.line != 0 ? first->source() : table.get(first->str())->source();
  return StrayKey{std::string(first->str()), where};
}

}  // namespace arpipe
