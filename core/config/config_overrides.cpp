// `--set section.key=value` overrides: each is parsed as one TOML assignment and merged into the
// parsed file, so the schema walk checks it like the file's own keys.
#include "core/config/config_overrides.h"
#include "core/config/toml_text.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <optional>

#include "core/config/toml_section.h"

namespace arpipe {

namespace {

[[noreturn]] void override_error(const std::string& label, const std::string& what) {
  throw TomlInputError(fmt::format("{}: {}", label, what));
}

bool is_bare_key(std::string_view key) {
  return !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

// Unquoted words ("fast", "out/run1") are taken as strings, so a shell need not quote quotes.
bool looks_like_bare_word(std::string_view value) {
  return !value.empty() && std::all_of(value.begin(), value.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::strchr("_-./:+", c) != nullptr;
  });
}

void merge_override(toml::table& target, toml::table& source, const std::string& prefix, const std::string& label);

// "render.objects.0.scale": a table of integer keys, merged into the existing array's elements.
void merge_override_into_array(toml::array& target, toml::table& source, const std::string& prefix,
                               const std::string& label) {
  for (auto&& [key, value] : source) {
    size_t index = 0;
    const std::string text(key.str());
    // from_chars, not stoul: an index of 30 digits is "not an index", not std::out_of_range's "stoul".
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), index);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() || index >= target.size())
      override_error(label, fmt::format("'{}' has {} elements; '{}' is not an index into it", prefix,
                                        target.size(), text));
    const std::string element = fmt::format("{}[{}]", prefix, index);
    if (value.is_table() && !value.as_table()->is_inline()) {
      if (!target[index].is_table()) override_error(label, fmt::format("'{}' is not a table", element));
      merge_override(*target[index].as_table(), *value.as_table(), element, label);
    } else {
      target.erase(target.cbegin() + static_cast<std::ptrdiff_t>(index));
      target.insert(target.cbegin() + static_cast<std::ptrdiff_t>(index), std::move(value));
    }
  }
}

// The dotted path of the first implicit table below `node` that is indexed like an array ("bundle.0").
std::optional<std::string> first_indexed_path(const toml::node& node, const std::string& dotted) {
  if (!node.is_table() || node.as_table()->is_inline()) return std::nullopt;
  for (auto&& [key, value] : *node.as_table()) {
    if (!key.str().empty() && std::isdigit(static_cast<unsigned char>(key.str().front()))) return dotted;
    if (auto found = first_indexed_path(value, fmt::format("{}.{}", dotted, key.str()))) return found;
  }
  return std::nullopt;
}

// Dotted keys make implicit (non-inline) tables: those descend; any other value replaces the key.
void merge_override(toml::table& target, toml::table& source, const std::string& prefix, const std::string& label) {
  for (auto&& [key, value] : source) {
    const std::string dotted = prefix.empty() ? std::string(key.str()) : fmt::format("{}.{}", prefix, key.str());
    toml::node* existing = target.get(key.str());
    if (existing != nullptr && value.is_table() && !value.as_table()->is_inline()) {
      if (existing->is_table()) {
        merge_override(*existing->as_table(), *value.as_table(), dotted, label);
        continue;
      }
      if (existing->is_array()) {
        merge_override_into_array(*existing->as_array(), *value.as_table(), dotted, label);
        continue;
      }
      override_error(label, fmt::format("'{}' is {}, not a table", dotted, toml_type_phrase(*existing)));
    }
    if (existing == nullptr)
      if (const auto indexed = first_indexed_path(value, dotted))
        override_error(label, fmt::format("'{}' is not in the file, so it has no elements to index; set the whole "
                                          "array instead, e.g. {}=[{{...}}]",
                                          *indexed, *indexed));
    target.insert_or_assign(key, std::move(value));
  }
}

// The parsed override must be exactly the one key it names: a chain of single-entry tables down to
// one value (a newline in the value would otherwise let it add tables of its own).
bool is_single_assignment(const toml::table& parsed, std::string_view key) {
  const toml::table* table = &parsed;
  size_t start = 0;
  while (true) {
    const size_t dot = key.find('.', start);
    const std::string_view part = key.substr(start, dot == std::string_view::npos ? dot : dot - start);
    if (table->size() != 1 || !table->contains(part)) return false;
    if (dot == std::string_view::npos) return true;
    const toml::node* next = table->get(part);
    if (!next->is_table()) return false;
    table = next->as_table();
    start = dot + 1;
  }
}

}  // namespace

void apply_override(toml::table& root, const std::string& assignment) {
  const std::string label = override_label(assignment);
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos) override_error(label, "expected section.key=value");
  const std::string_view key = trim_space(std::string_view(assignment).substr(0, equals));
  const std::string_view value = trim_space(std::string_view(assignment).substr(equals + 1));
  size_t start = 0;
  while (true) {
    const size_t dot = key.find('.', start);
    if (!is_bare_key(key.substr(start, dot == std::string_view::npos ? dot : dot - start)))
      override_error(label, fmt::format("'{}' is not a dotted key such as track.family", printable(key)));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  // One value on one line: a line break (or another control character) could start new tables.
  const auto control = std::find_if(value.begin(), value.end(), [](char c) {
    return (static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f;
  });
  if (control != value.end())
    override_error(label, fmt::format("the value of '{}' contains {}; an override is exactly one TOML value on one "
                                      "line (escape it inside a quoted string, e.g. \"a\\nb\")",
                                      key, *control == '\n' ? "a newline" : "a control character"));
  toml::table parsed;
  try {
    parsed = toml::parse(fmt::format("{} = {}", key, value), std::string_view(label));
  } catch (const toml::parse_error& e) {
    const std::string text = fmt::format("{} = {}", key, value);
    if (auto message = toml_number_range_error(e, text, label)) throw TomlInputError(*message);
    if (!looks_like_bare_word(value))
      override_error(label, fmt::format("the value is not valid TOML ({}); quote strings", e.description()));
    parsed = toml::parse(fmt::format("{} = {}", key, toml_quoted(value)), std::string_view(label));
  }
  if (!is_single_assignment(parsed, key))
    override_error(label, fmt::format("the value of '{}' is not exactly one TOML value", key));
  merge_override(root, parsed, "", label);
}

}  // namespace arpipe
