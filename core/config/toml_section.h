// The one TOML section reader of the project: every TOML loader (the daemon config, simulator
// scenes, calibration boards, the V4L2 stand-in's config) reads its file through it, so all of them
// check types and ranges alike, report unknown keys alike, and word their messages alike:
//
//   file:line:col: dotted.key: expected <what>, found <what was there>
//   a.toml:3:9: render.lens_canvas_scale: expected a number in [1, 4], found 7.0
//   a.toml:5:1: render.foo: unknown key; allowed keys in [render]: enabled, lens, lens_canvas_scale
//
// A TomlSection wraps one table with its dotted path ("render", "render.objects[1]") and the source
// name. Each typed read takes the key and the value to keep when the key is absent, checks the
// value, and remembers the key, so that reject_stray_keys() can name the first key (in file order)
// that nothing asked for. Every problem throws TomlInputError; loaders may catch and wrap it.
//
//   toml::table root = parse_toml(text, "scene.toml");
//   TomlSection file(root, "scene.toml");
//   TomlSection camera = file.section("camera").value_or(TomlSection::empty(file, "camera"));
//   double fps = camera.number("fps", 30.0, NumberRange::above(0));
//   Pacing pacing = camera.choice("pacing", Pacing::Timestamps, kPacingNames);
//   for (const TomlSection& object : file.sections("object", 64)) { object.vec3("position_m", {0, 0, 0}); }
//   file.reject_stray_keys();  // this section and every section opened from it
#pragma once

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/choice_names.h"
#include "core/config/toml_text.h"
#include "core/config/toml_type_phrase.h"
#include "core/config/value_ranges.h"  // "a string", "a table": what a node is, for "found ..."

namespace arpipe {

// Bad TOML input; what() is "place: key: what is wrong".
class TomlInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses TOML text. A syntax error throws TomlInputError with its place; a number beyond 64 bits
// (which toml++ calls a syntax error) is reported as "key: expected ..., found <the number>".
toml::table parse_toml(std::string_view text, const std::string& source_name);

// The message for a number toml++ could not hold in 64 bits (a parse_error to it), or nullopt for
// any other syntax error; text is what was parsed. For loaders that parse on their own (overrides).
std::optional<std::string> toml_number_range_error(const toml::parse_error& e, std::string_view text,
                                                   const std::string& source_name);

// "file:line:col" of a region; a region without a place is the source name alone; a region made
// from a `--set` override is the override's own label ("override 'a.b=1'").
std::string toml_place(const toml::source_region& region, const std::string& source_name);

// The label given to the text of a `--set` override, so toml_place() names the override.
std::string override_label(std::string_view assignment);

class TomlSection {
 public:
  // The top level of a parsed file. base_dir: what relative paths (path()) are resolved against;
  // empty keeps them as written.
  TomlSection(const toml::table& root, std::string source_name, std::filesystem::path base_dir = {});

  // A section with no keys at `dotted` below `parent`, for an absent table whose defaults apply.
  static TomlSection empty(const TomlSection& parent, std::string_view key);

  const std::string& dotted() const { return dotted_; }  // "" at the top level
  std::string key_path(std::string_view key) const;         // "render.lens"
  const std::string& source_name() const;
  const toml::table& table() const { return *table_; }
  bool has(std::string_view key) const { return table_->contains(key); }

  // ---- Typed reads: fallback when absent; TomlInputError when the value does not fit. ----------
  bool boolean(std::string_view key, bool fallback) const;
  int64_t integer(std::string_view key, int64_t fallback, IntRange range = {}) const;
  template <class Int>
  Int integer_as(std::string_view key, Int fallback, IntRange range = {}) const {
    range.min = std::max<int64_t>(range.min, std::numeric_limits<Int>::min());
    range.max = std::min<int64_t>(range.max, std::numeric_limits<Int>::max());
    return static_cast<Int>(integer(key, fallback, range));
  }
  // Integers are numbers too (size_m = 1 means 1.0); the value must be finite.
  double number(std::string_view key, double fallback, const NumberRange& range = {}) const;
  std::string string(std::string_view key, const std::string& fallback) const;
  // A string naming a file or directory; relative names are resolved against the base directory.
  std::filesystem::path path(std::string_view key, const std::filesystem::path& fallback) const;
  // Exactly N numbers ([x, y, z] for N = 3), each in range.
  template <size_t N>
  std::array<double, N> numbers(std::string_view key, const std::array<double, N>& fallback,
                                const NumberRange& range = {}) const {
    std::array<double, N> out = fallback;
    read_numbers(key, out.data(), N, range);
    return out;
  }
  std::array<double, 3> vec3(std::string_view key, const std::array<double, 3>& fallback,
                             const NumberRange& range = {}) const {
    return numbers<3>(key, fallback, range);
  }
  // Any count up to max_count.
  std::vector<double> number_list(std::string_view key, std::vector<double> fallback, const NumberRange& range = {},
                                  size_t max_count = 4096) const;
  // A name from the choice's name table (aliases accepted).
  template <class E>
  E choice(std::string_view key, E fallback, ChoiceNames<E> names) const {
    const toml::node* node = read_node(key);
    if (node == nullptr) return fallback;
    const std::string expected = "one of " + choice_list(names);
    if (!node->is_string()) fail_at(*node, key_path(key), expected, std::string(toml_type_phrase(*node)));
    const auto value = choice_value(names, node->as_string()->get());
    if (!value) fail_at(*node, key_path(key), expected, toml_quoted(node->as_string()->get()));
    return *value;
  }
  template <class E, size_t N>
  E choice(std::string_view key, E fallback, const ChoiceName<E> (&names)[N]) const {
    return choice(key, fallback, ChoiceNames<E>(names));
  }
  // A string turned into a value by `parse` (nullopt: not valid), e.g. a camera response "gamma:2.2".
  template <class T>
  T parsed(std::string_view key, T fallback, const std::function<std::optional<T>(std::string_view)>& parse,
           const std::string& expected) const {
    const toml::node* node = read_node(key);
    if (node == nullptr) return fallback;
    if (!node->is_string()) fail_at(*node, key_path(key), expected, std::string(toml_type_phrase(*node)));
    const auto value = parse(node->as_string()->get());
    if (!value) fail_at(*node, key_path(key), expected, toml_quoted(node->as_string()->get()));
    return *value;
  }

  // A table below this one; nullopt when absent.
  std::optional<TomlSection> section(std::string_view key) const;
  // [[key]] tables (or an inline array of inline tables), named "key[0]", "key[1]", ...; none when
  // absent (has(key) tells an absent key from an empty array).
  std::vector<TomlSection> sections(std::string_view key, size_t max_count = 1'000'000) const;
  // The raw node (remembered as read), for a value no typed read fits; nullptr when absent.
  const toml::node* node(std::string_view key) const { return read_node(key); }
  // Marks a key as known without reading it (e.g. read only under some condition).
  void allow(std::string_view key) const;

  // ---- Messages ----------------------------------------------------------------------------------
  // "place: dotted.key: expected <expected>, found <found>", placed at the key's value (or at this
  // table when the key is absent).
  [[noreturn]] void fail(std::string_view key, const std::string& expected, const std::string& found) const;
  // "place: dotted.key: <what>", for problems that are not "expected, found".
  [[noreturn]] void fail_with(std::string_view key, const std::string& what) const;
  // As fail(), at a given node with a given dotted name (an array item: "render.ambient[1]").
  [[noreturn]] void fail_at(const toml::node& node, const std::string& dotted, const std::string& expected,
                            const std::string& found) const;
  // Where the key's value is ("a.toml:3:9"), or this table when it is absent.
  std::string place(std::string_view key) const;

  // Throws on the first key, in file order, of this section or any section opened from it that no
  // read asked for: "place: render.foo: unknown key; allowed keys in [render]: a, b, c".
  void reject_stray_keys() const;

 private:
  struct Shared;
  struct Record;
  TomlSection(const toml::table& table, std::string dotted, std::string header, std::shared_ptr<const Shared> shared,
              std::shared_ptr<Record> record);

  const toml::node* read_node(std::string_view key) const;
  double number_at(const toml::node& node, const std::string& dotted, const NumberRange& range) const;
  void read_numbers(std::string_view key, double* out, size_t count, const NumberRange& range) const;
  TomlSection child(const toml::table& table, std::string dotted, std::string header) const;

  const toml::table* table_;
  std::string dotted_;
  std::string header_;  // how the stray-key message names the table: "[render]", "[[track.bundle]]"
  std::shared_ptr<const Shared> shared_;
  std::shared_ptr<Record> record_;
};

}  // namespace arpipe
