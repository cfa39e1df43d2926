// TomlSection: typed reads over one toml++ table, remembered for the stray-key check.
#include "core/config/toml_section.h"
#include "core/config/toml_text.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <tuple>

#include "core/config/toml_stray_key.h"

namespace arpipe {

namespace {

constexpr std::string_view kOverridePrefix = "override '";

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// The quoted token of a toml++ error description ("'1e400' could not be ...").
std::optional<std::string_view> quoted_token(std::string_view description) {
  const size_t open = description.find('\'');
  const size_t close = open == std::string_view::npos ? open : description.find('\'', open + 1);
  if (close == std::string_view::npos) return std::nullopt;
  return description.substr(open + 1, close - open - 1);
}

// toml++ rejects numbers beyond 64 bits as syntax errors ("'1e400' could not be interpreted as a
// value", "... is not representable in 64 bits"); this says what was expected of such a number.
std::optional<std::string> out_of_range_expected(std::string_view description) {
  if (description.starts_with("Error while parsing floating-point") &&
      description.find("could not be interpreted") != std::string_view::npos)
    return "a number within a 64-bit float (magnitude at most about 1.8e308)";
  if (description.find("is not representable in 64 bits") != std::string_view::npos)
    return "an integer within 64 bits [-9223372036854775808, 9223372036854775807]";
  return std::nullopt;
}

// The 1-based column where `token` starts on line `line` (after the '=').
std::optional<toml::source_index> token_column(std::string_view text, uint32_t line, std::string_view token) {
  size_t begin = 0;
  for (uint32_t number = 1; number < line; ++number) {
    begin = text.find('\n', begin);
    if (begin == std::string_view::npos) return std::nullopt;
    ++begin;
  }
  const std::string_view content = text.substr(begin, text.find('\n', begin) - begin);
  const size_t equals = content.find('=');
  const size_t at = content.find(token, equals == std::string_view::npos ? 0 : equals);
  if (at == std::string_view::npos) return std::nullopt;
  return static_cast<toml::source_index>(at + 1);
}

// The dotted key assigned on line `line` (1-based) of a TOML text, with the table header above it
// ("render.lens_canvas_scale", "render.objects[1].scale"): a line scan for messages only.
std::string key_on_line(std::string_view text, uint32_t line) {
  std::string table;
  std::map<std::string, int> array_counts;
  size_t begin = 0;
  for (uint32_t number = 1; begin <= text.size(); ++number) {
    size_t end = text.find('\n', begin);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view content = trim_space(text.substr(begin, end - begin));
    if (number == line) {
      const size_t equals = content.find('=');
      const std::string key(trim_space(content.substr(0, equals == std::string_view::npos ? 0 : equals)));
      if (key.empty()) return table;
      return table.empty() ? key : table + "." + key;
    }
    if (content.starts_with("[[")) {
      const size_t close = content.find("]]");
      const std::string name(trim_space(content.substr(2, close == std::string_view::npos ? 0 : close - 2)));
      table = fmt::format("{}[{}]", name, array_counts[name]++);
    } else if (content.starts_with("[")) {
      const size_t close = content.find(']');
      table = std::string(trim_space(content.substr(1, close == std::string_view::npos ? 0 : close - 1)));
    }
    if (end == text.size()) break;
    begin = end + 1;
  }
  return table;
}

bool earlier(const toml::source_region& a, const toml::source_region& b) {
  return std::tie(a.begin.line, a.begin.column) < std::tie(b.begin.line, b.begin.column);
}

}  // namespace

// ---- Free functions ------------------------------------------------------------------------------

std::string toml_place(const toml::source_region& region, const std::string& source_name) {
  if (!region.path || region.begin.line == 0) return source_name;
  const std::string& path = *region.path;
  if (path.starts_with(kOverridePrefix)) return path;
  return fmt::format("{}:{}:{}", path, region.begin.line, region.begin.column);
}

std::string override_label(std::string_view assignment) {
  return fmt::format("{}{}'", kOverridePrefix, printable(assignment));
}

std::optional<std::string> toml_number_range_error(const toml::parse_error& e, std::string_view text,
                                                   const std::string& source_name) {
  const auto expected = out_of_range_expected(e.description());
  const auto token = quoted_token(e.description());
  if (!expected || !token) return std::nullopt;
  // toml++ places the error after the number; the message points at the number itself.
  toml::source_region where = e.source();
  where.begin.column = token_column(text, where.begin.line, *token).value_or(where.begin.column);
  return fmt::format("{}: {}: expected {}, found {}", toml_place(where, source_name), key_on_line(text, where.begin.line),
                     *expected, *token);
}

toml::table parse_toml(std::string_view text, const std::string& source_name) {
  try {
    return toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    if (auto message = toml_number_range_error(e, text, source_name)) throw TomlInputError(*message);
    throw TomlInputError(
        fmt::format("{}: TOML syntax error: {}", toml_place(e.source(), source_name), e.description()));
  }
}

// ---- Ranges ---------------------------------------------------------------------------------------

NumberRange NumberRange::closed(double lo, double hi) {
  return rule([=](double v) { return v >= lo && v <= hi; }, fmt::format("[{}, {}]", bound_text(lo), bound_text(hi)));
}
NumberRange NumberRange::open_closed(double lo, double hi) {
  return rule([=](double v) { return v > lo && v <= hi; }, fmt::format("({}, {}]", bound_text(lo), bound_text(hi)));
}
NumberRange NumberRange::closed_open(double lo, double hi) {
  return rule([=](double v) { return v >= lo && v < hi; }, fmt::format("[{}, {})", bound_text(lo), bound_text(hi)));
}
NumberRange NumberRange::at_least(double lo) {
  return rule([=](double v) { return v >= lo; }, fmt::format(">= {}", bound_text(lo)));
}
NumberRange NumberRange::above(double lo) {
  return rule([=](double v) { return v > lo; }, fmt::format("> {}", bound_text(lo)));
}

std::string NumberRange::phrase() const {
  std::string out = "a number";
  if (!interval.empty()) out += (interval.front() == '[' || interval.front() == '(' ? " in " : " ") + interval;
  if (!unit.empty()) out += fmt::format(" ({})", unit);
  return out;
}

std::string IntRange::interval() const {
  constexpr int64_t kLow = std::numeric_limits<int64_t>::min();
  constexpr int64_t kHigh = std::numeric_limits<int64_t>::max();
  // The limits of a narrower integer type count as "no limit" too.
  const bool has_min = min != kLow && min != std::numeric_limits<int>::min();
  const bool has_max = max != kHigh && max != std::numeric_limits<int>::max();
  if (has_min && has_max) return fmt::format("[{}, {}]", min, max);
  if (has_min) return fmt::format(">= {}", min);
  if (has_max) return fmt::format("<= {}", max);
  return {};
}

std::string IntRange::phrase() const {
  const std::string range = interval();
  if (range.empty()) return "an integer";
  return fmt::format("an integer {}{}", range.front() == '[' ? "in " : "", range);
}

// ---- TomlSection ----------------------------------------------------------------------------------

struct TomlSection::Shared {
  std::string source_name;
  std::filesystem::path base_dir;
};

// What was asked of one table, and the tables opened from it: for reject_stray_keys().
struct TomlSection::Record {
  const toml::table* table = nullptr;
  std::string dotted;
  std::string header;
  std::vector<std::string> asked;
  std::vector<std::shared_ptr<Record>> children;
};

TomlSection::TomlSection(const toml::table& root, std::string source_name, std::filesystem::path base_dir)
    : TomlSection(root, "", "the top level",
                  std::make_shared<const Shared>(Shared{std::move(source_name), std::move(base_dir)}),
                  std::make_shared<Record>()) {}

TomlSection::TomlSection(const toml::table& table, std::string dotted, std::string header,
                         std::shared_ptr<const Shared> shared, std::shared_ptr<Record> record)
    : table_(&table), dotted_(std::move(dotted)), header_(std::move(header)), shared_(std::move(shared)),
      record_(std::move(record)) {
  record_->table = table_;
  record_->dotted = dotted_;
  record_->header = header_;
}

TomlSection TomlSection::child(const toml::table& table, std::string dotted, std::string header) const {
  // Opening the same table again (a later check that points at a key) shares what was asked of it.
  for (const auto& existing : record_->children)
    if (existing->table == &table) return TomlSection(table, std::move(dotted), std::move(header), shared_, existing);
  auto record = std::make_shared<Record>();
  record_->children.push_back(record);
  return TomlSection(table, std::move(dotted), std::move(header), shared_, std::move(record));
}

TomlSection TomlSection::empty(const TomlSection& parent, std::string_view key) {
  static const toml::table kEmpty;
  parent.allow(key);
  const std::string dotted = parent.key_path(key);
  return parent.child(kEmpty, dotted, fmt::format("[{}]", dotted));
}

std::string TomlSection::key_path(std::string_view key) const {
  return dotted_.empty() ? std::string(key) : fmt::format("{}.{}", dotted_, key);
}

const std::string& TomlSection::source_name() const { return shared_->source_name; }

void TomlSection::allow(std::string_view key) const {
  if (std::find(record_->asked.begin(), record_->asked.end(), key) == record_->asked.end())
    record_->asked.emplace_back(key);
}

const toml::node* TomlSection::read_node(std::string_view key) const {
  allow(key);
  return table_->get(key);
}

std::string TomlSection::place(std::string_view key) const {
  const toml::node* node = table_->get(key);
  return toml_place(node != nullptr ? node->source() : table_->source(), shared_->source_name);
}

void TomlSection::fail(std::string_view key, const std::string& expected, const std::string& found) const {
  fail_with(key, fmt::format("expected {}, found {}", expected, found));
}

void TomlSection::fail_with(std::string_view key, const std::string& what) const {
  throw TomlInputError(fmt::format("{}: {}: {}", place(key), key_path(key), what));
}

void TomlSection::fail_at(const toml::node& node, const std::string& dotted, const std::string& expected,
                          const std::string& found) const {
  throw TomlInputError(
      fmt::format("{}: {}: expected {}, found {}", toml_place(node.source(), shared_->source_name), dotted, expected, found));
}

bool TomlSection::boolean(std::string_view key, bool fallback) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return fallback;
  if (!node->is_boolean()) fail(key, "a boolean (true or false)", std::string(toml_type_phrase(*node)));
  return node->as_boolean()->get();
}

int64_t TomlSection::integer(std::string_view key, int64_t fallback, IntRange range) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return fallback;
  if (!node->is_integer()) fail(key, range.phrase(), std::string(toml_type_phrase(*node)));
  const int64_t value = node->as_integer()->get();
  if (value < range.min || value > range.max) fail(key, range.phrase(), fmt::format("{}", value));
  return value;
}

double TomlSection::number_at(const toml::node& node, const std::string& dotted, const NumberRange& range) const {
  double value = 0;
  if (node.is_integer())
    value = static_cast<double>(node.as_integer()->get());
  else if (node.is_floating_point())
    value = node.as_floating_point()->get();
  else
    fail_at(node, dotted, range.phrase(), std::string(toml_type_phrase(node)));
  if (!std::isfinite(value)) fail_at(node, dotted, "a finite number", toml_float(value));
  if (range.ok && !range.ok(value)) fail_at(node, dotted, range.phrase(), toml_float(value));
  return value;
}

double TomlSection::number(std::string_view key, double fallback, const NumberRange& range) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return fallback;
  return number_at(*node, key_path(key), range);
}

std::string TomlSection::string(std::string_view key, const std::string& fallback) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return fallback;
  if (!node->is_string()) fail(key, "a string", std::string(toml_type_phrase(*node)));
  return node->as_string()->get();
}

std::filesystem::path TomlSection::path(std::string_view key, const std::filesystem::path& fallback) const {
  if (!has(key)) {
    allow(key);
    return fallback;
  }
  std::filesystem::path out = string(key, "");
  if (!out.empty() && out.is_relative() && !shared_->base_dir.empty()) out = (shared_->base_dir / out).lexically_normal();
  return out;
}

void TomlSection::read_numbers(std::string_view key, double* out, size_t count, const NumberRange& range) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return;
  const std::string item = range.interval.empty() && range.unit.empty() ? "numbers" : "numbers, each " + range.phrase();
  const std::string expected = count == 3 ? fmt::format("an array of 3 {} [x, y, z]", item)
                                          : fmt::format("an array of {} {}", count, item);
  if (!node->is_array()) fail(key, expected, std::string(toml_type_phrase(*node)));
  const toml::array& array = *node->as_array();
  if (array.size() != count) fail(key, expected, fmt::format("{} items", array.size()));
  std::vector<double> values(count);
  for (size_t i = 0; i < count; ++i) values[i] = number_at(array[i], fmt::format("{}[{}]", key_path(key), i), range);
  std::copy(values.begin(), values.end(), out);
}

std::vector<double> TomlSection::number_list(std::string_view key, std::vector<double> fallback,
                                             const NumberRange& range, size_t max_count) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return fallback;
  const std::string expected = fmt::format("an array of at most {} numbers ({} each)", max_count, range.phrase());
  if (!node->is_array()) fail(key, expected, std::string(toml_type_phrase(*node)));
  const toml::array& array = *node->as_array();
  if (array.size() > max_count) fail(key, expected, fmt::format("{} numbers", array.size()));
  std::vector<double> out;
  for (size_t i = 0; i < array.size(); ++i) out.push_back(number_at(array[i], fmt::format("{}[{}]", key_path(key), i), range));
  return out;
}

std::optional<TomlSection> TomlSection::section(std::string_view key) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return std::nullopt;
  if (!node->is_table()) fail(key, "a table", std::string(toml_type_phrase(*node)));
  const std::string dotted = key_path(key);
  return child(*node->as_table(), dotted, fmt::format("[{}]", dotted));
}

std::vector<TomlSection> TomlSection::sections(std::string_view key, size_t max_count) const {
  const toml::node* node = read_node(key);
  if (node == nullptr) return {};
  const std::string dotted = key_path(key);
  if (!node->is_array()) fail(key, "an array of tables", std::string(toml_type_phrase(*node)));
  const toml::array& array = *node->as_array();
  if (array.size() > max_count)
    fail(key, fmt::format("at most {} [[{}]] tables", max_count, dotted), fmt::format("{}", array.size()));
  std::vector<TomlSection> out;
  for (size_t i = 0; i < array.size(); ++i) {
    const std::string item = fmt::format("{}[{}]", dotted, i);
    if (!array[i].is_table()) fail_at(array[i], item, "a table", std::string(toml_type_phrase(array[i])));
    out.push_back(child(*array[i].as_table(), item, fmt::format("[[{}]]", dotted)));
  }
  return out;
}

void TomlSection::reject_stray_keys() const {
  // The earliest stray key over this record and every record below it.
  std::optional<StrayKey> first;
  const Record* first_record = nullptr;
  std::vector<const Record*> pending{record_.get()};
  while (!pending.empty()) {
    const Record* record = pending.back();
    pending.pop_back();
    for (const auto& child : record->children) pending.push_back(child.get());
    const std::vector<std::string_view> allowed(record->asked.begin(), record->asked.end());
    auto stray = first_stray_key(*record->table, allowed);
    if (stray && (!first || earlier(stray->where, first->where))) {
      first = std::move(stray);
      first_record = record;
    }
  }
  if (!first) return;
  const std::string dotted =
      first_record->dotted.empty() ? first->name : fmt::format("{}.{}", first_record->dotted, first->name);
  throw TomlInputError(fmt::format("{}: {}: unknown key; allowed keys in {}: {}",
                                   toml_place(first->where, shared_->source_name), dotted, first_record->header,
                                   join(first_record->asked)));
}

}  // namespace arpipe
