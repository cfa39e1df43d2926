// The one name table of a choice (an enum read from text): each value's name, plus old names
// still accepted as aliases. Reading, writing (results, logs, `arpipe config --defaults`) and
// messages all go through the table, so a name is spelled in exactly one place.
//
//   enum class Pacing { Timestamps, Fast };
//   inline constexpr ChoiceName<Pacing> kPacingNames[] = {
//       {"timestamps", Pacing::Timestamps}, {"fast", Pacing::Fast}, {"realtime", Pacing::Timestamps, true}};
//   choice_name(kPacingNames, Pacing::Fast)   -> "fast"
//   choice_value(kPacingNames, "realtime")    -> Pacing::Timestamps
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace arpipe {

template <class E>
struct ChoiceName {
  std::string_view name;
  E value;
  bool alias = false;  // an old name: accepted when read, never written
};

template <class E>
using ChoiceNames = std::span<const ChoiceName<E>>;

// The value's own (non-alias) name; "" for a value missing from the table.
template <class E>
std::string_view choice_name(ChoiceNames<E> names, E value) {
  for (const auto& entry : names)
    if (!entry.alias && entry.value == value) return entry.name;
  return {};
}

template <class E>
std::optional<E> choice_value(ChoiceNames<E> names, std::string_view text) {
  for (const auto& entry : names)
    if (entry.name == text) return entry.value;
  return std::nullopt;
}

// The same for a name table given as an array (kLensModeNames).
template <class E, size_t N>
std::string_view choice_name(const ChoiceName<E> (&names)[N], E value) {
  return choice_name(ChoiceNames<E>(names), value);
}
template <class E, size_t N>
std::optional<E> choice_value(const ChoiceName<E> (&names)[N], std::string_view text) {
  return choice_value(ChoiceNames<E>(names), text);
}

// "\"a\", \"b\", \"c\"": the names to offer (aliases not shown).
template <class E>
std::string choice_list(ChoiceNames<E> names) {
  std::string out;
  for (const auto& entry : names) {
    if (entry.alias) continue;
    if (!out.empty()) out += ", ";
    out += '"';
    out += entry.name;
    out += '"';
  }
  return out;
}

// "; old names: \"seed\" (= \"intraframe-warp\")", or "" without aliases: for help texts.
template <class E>
std::string choice_aliases(ChoiceNames<E> names) {
  std::string out;
  for (const auto& entry : names) {
    if (!entry.alias) continue;
    out += out.empty() ? "; old names: " : ", ";
    out += '"';
    out += entry.name;
    out += "\" (= \"";
    out += choice_name(names, entry.value);
    out += "\")";
  }
  return out;
}

}  // namespace arpipe
