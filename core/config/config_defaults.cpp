// `arpipe config --defaults`: the schema rows (config.h's visit functions) walked over a default
// Config, each key printed with its default and a comment made of its rule and its help.
#include <fmt/format.h>

#include <numbers>

#include "core/config/config.h"
#include "core/config/toml_text.h"
#include "core/track/tag_family.h"

namespace arpipe {

namespace {

constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;

std::string vec_text(const Vec3& v) {
  return fmt::format("[{}, {}, {}]", toml_float(v[0]), toml_float(v[1]), toml_float(v[2]));
}

// "\"a\", \"b\" or \"c\""
std::string names_text(const std::vector<std::string_view>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + toml_quoted(names[i]);
  return out;
}

std::string range_text(const NumberRange& range) {
  std::string out = range.interval;
  if (!range.unit.empty()) out += (out.empty() ? "" : " ") + fmt::format("({})", range.unit);
  return out;
}

// The visitor that prints rows: "key = default   # rule: help".
class RowWriter {
 public:
  explicit RowWriter(std::string& out) : out_(out) {}

  void key(std::string_view name, bool value, std::string_view help) { row(name, value ? "true" : "false", "", help); }
  void key(std::string_view name, const std::string& value, std::string_view help) { row(name, toml_quoted(value), "", help); }
  void key(std::string_view name, const std::filesystem::path& value, std::string_view help) {
    row(name, toml_quoted(value.string()), "", help);
  }
  void key(std::string_view name, double value, std::string_view help) { row(name, toml_float(value), "", help); }
  void key(std::string_view name, const Vec3& value, std::string_view help) { row(name, vec_text(value), "", help); }
  template <class Int>
  void key(std::string_view name, Int value, const IntRange& range, std::string_view help) {
    row(name, fmt::format("{}", value), range.interval(), help);
  }
  void key(std::string_view name, int value, const OneOfInts& rule, std::string_view help) {
    std::string values;
    for (size_t i = 0; i < rule.values.size(); ++i)
      values += fmt::format("{}{}", i == 0 ? "" : i + 1 == rule.values.size() ? " or " : ", ", rule.values[i]);
    row(name, fmt::format("{}", value), values, help);
  }
  void key(std::string_view name, double value, const NumberRange& range, std::string_view help) {
    row(name, toml_float(value), range_text(range), help);
  }
  void key(std::string_view name, const Vec3& value, const NumberRange& range, std::string_view help) {
    row(name, vec_text(value), range_text(range) + (range.interval.empty() ? "" : " each"), help);
  }
  void key(std::string_view name, double value_rad, const Degrees& rule, std::string_view help) {
    row(name, toml_float(value_rad * kDegreesPerRadian), range_text(rule.range), help);
  }
  void key(std::string_view name, const std::vector<double>& values, const NumberCount& rule, std::string_view help) {
    std::string text = "[";
    for (size_t i = 0; i < values.size(); ++i) text += (i ? ", " : "") + toml_float(values[i]);
    row(name, text + "]", rule.phrase + (range_text(rule.range).empty() ? "" : ", each " + range_text(rule.range)), help);
  }
  void key(std::string_view name, const Vec3& value_rad, const Degrees& rule, std::string_view help) {
    row(name, vec_text(kDegreesPerRadian * value_rad), range_text(rule.range) + (rule.range.interval.empty() ? "" : " each"), help);
  }
  void key(std::string_view name, ProxyRoles value, const ProxyRoleNames&, std::string_view help) {
    std::string names;
    for (size_t i = 0; i < std::size(kProxyRoleNames); ++i)
      if (proxy_role(value, i)) names += (names.empty() ? "" : ", ") + toml_quoted(kProxyRoleNames[i]);
    row(name, "[" + names + "]", "distinct names", help);
  }
  void key(std::string_view name, int64_t value_ns, const MillisecondsAsNs& rule, std::string_view help) {
    row(name, toml_float(double(value_ns) * 1e-6), range_text(rule.range), help);
  }
  void key(std::string_view name, const std::string& value, const OneOf& rule, std::string_view help) {
    row(name, toml_quoted(value), names_text(rule.names), help);
  }
  void key(std::string_view name, const std::string& value, const NotEmpty&, std::string_view help) {
    row(name, toml_quoted(value), "", help);
  }
  void key(std::string_view name, const std::string& value, const TagFamilyName&, std::string_view help) {
    row(name, toml_quoted(value), "one of " + joined_tag_family_names(), help);
  }
  void key(std::string_view name, const CameraResponse& value, const CameraResponseName&, std::string_view help) {
    row(name, toml_quoted(value.name()), "\"srgb\", \"linear\" or \"gamma:<g>\" (0 < g)", help);
  }

  template <class E, size_t N>
  void key(std::string_view name, E value, const ChoiceName<E> (&names)[N], std::string_view help) {
    std::vector<std::string_view> shown;
    for (const auto& entry : names)
      if (!entry.alias) shown.push_back(entry.name);
    row(name, toml_quoted(choice_name(names, value)), names_text(shown) + choice_aliases(ChoiceNames<E>(names)), help);
  }

  template <class Section>
  void section(std::string_view name, Section& member, std::string_view help) {
    RowWriter sub(out_, path(name));
    sub.prefix_ = prefix_;  // inside a commented-out example, commented out too
    sub.header_ = fmt::format("[{}]", sub.dotted_);
    sub.header_help_ = help;
    visit(sub, member);
  }
  template <class Element>
  void sections(std::string_view name, std::vector<Element>& member, std::string_view help) {
    out_ += fmt::format("\n# {}\n", help);
    // An empty list by default: one element shown commented out, with its keys' defaults.
    std::vector<Element> shown = member;
    const bool example = shown.empty();
    if (example) shown.emplace_back();
    for (Element& element : shown) {
      RowWriter sub(out_, path(name));
      sub.prefix_ = example ? "# " : prefix_;
      out_ += fmt::format("{}[[{}]]\n", sub.prefix_, sub.dotted_);
      visit(sub, element);
    }
  }
  // A part that is on only when the config has its table (a sink): shown commented out, with the
  // values it has when the table is there.
  template <class Section>
  void switched_section(std::string_view name, Section& member, std::string_view help) {
    Section present = member;
    present.enabled = true;
    RowWriter sub(out_, path(name));
    sub.prefix_ = "# ";
    sub.header_ = fmt::format("[{}]", sub.dotted_);
    sub.header_help_ = help;
    sub.header_note_ = "; off unless the config has this table";
    visit(sub, present);
  }

 private:
  RowWriter(std::string& out, std::string dotted) : out_(out), dotted_(std::move(dotted)) {}

  std::string path(std::string_view name) const { return dotted_.empty() ? std::string(name) : fmt::format("{}.{}", dotted_, name); }

  // The table's header goes out before its first key, so a table of tables ([sinks]) has none.
  void flush_header() {
    if (header_.empty()) return;
    if (header_help_.empty())
      out_ += fmt::format("\n{}{}\n", prefix_, header_);
    else
      out_ += fmt::format("\n{:<31}# {}{}\n", prefix_ + header_ + " ", header_help_, header_note_);
    header_.clear();
  }

  void row(std::string_view name, const std::string& value, const std::string& rule, std::string_view help) {
    flush_header();
    const std::string assignment = fmt::format("{} = {}", name, value);
    std::string comment = rule;
    if (!help.empty()) comment += (comment.empty() ? "" : ": ") + std::string(help);
    if (comment.empty())
      out_ += prefix_ + assignment + "\n";
    else
      out_ += fmt::format("{:<32}# {}\n", prefix_ + assignment + " ", comment);
  }

  std::string& out_;
  std::string dotted_;
  std::string header_;
  std::string_view header_help_;
  std::string_view header_note_;
  std::string prefix_;  // "# " for a table shown commented out (a list empty by default, a sink)
};

}  // namespace

std::string default_config_toml() {
  std::string out =
      "# arpiped configuration: every key is optional and shows its default; unknown keys are errors.\n"
      "# Tables shown commented out are absent by default: no virtual objects, and no sink writes\n"
      "# until the config names it.\n"
      "# Units: metres, nanoseconds, and degrees for angles (the code works in radians).\n";
  Config defaults;
  RowWriter writer(out);
  visit(writer, defaults);
  return out;
}

}  // namespace arpipe
