#include "standin_config.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <unistd.h>

#include <set>

#include "core/config/text_file.h"
#include "core/config/toml_stray_key.h"
#include "core/config/toml_type_phrase.h"

namespace arpipe::standin {

namespace {

std::string place_of(const toml::source_region& region, const std::string& file) {
  return fmt::format("{}:{}:{}", file, region.begin.line, region.begin.column);
}

// Reads the keys of one table, each with the place of its value for messages.
class TableReader {
 public:
  TableReader(const toml::table& table, const std::string& file, std::string what)
      : table_(table), file_(file), what_(std::move(what)) {}

  [[noreturn]] void fail(const toml::node& node, const std::string& message) const {
    throw StandinConfigError(fmt::format("{}: {}", place_of(node.source(), file_), message));
  }
  [[noreturn]] void fail_here(const std::string& message) const { fail(table_, message); }

  void check_keys(const std::vector<std::string_view>& allowed) const {
    if (const auto stray = first_stray_key(table_, allowed)) {
      std::string list;
      for (const auto& key : allowed) list += (list.empty() ? "" : ", ") + std::string(key);
      throw StandinConfigError(fmt::format("{}: unknown key '{}' in {} (expected one of: {})",
                                           place_of(stray->where, file_), stray->name, what_, list));
    }
  }

  const toml::node* node(std::string_view key) const { return table_.get(key); }

  std::string string(std::string_view key, const std::string& fallback, bool required = false) const {
    const toml::node* n = node(key);
    if (n == nullptr) {
      if (required) fail_here(fmt::format("{} needs '{}' (a string)", what_, key));
      return fallback;
    }
    if (!n->is_string()) fail(*n, fmt::format("'{}' expected a string, got {}", key, toml_type_phrase(*n)));
    return std::string(*n->value<std::string>());
  }

  int64_t integer(std::string_view key, int64_t fallback, int64_t lo, int64_t hi, bool required = false) const {
    const toml::node* n = node(key);
    if (n == nullptr) {
      if (required) fail_here(fmt::format("{} needs '{}' (an integer)", what_, key));
      return fallback;
    }
    if (!n->is_integer()) fail(*n, fmt::format("'{}' expected an integer, got {}", key, toml_type_phrase(*n)));
    const int64_t v = *n->value<int64_t>();
    if (v < lo || v > hi) fail(*n, fmt::format("'{}' expected an integer in [{}, {}], got {}", key, lo, hi, v));
    return v;
  }

  bool boolean(std::string_view key, bool fallback) const {
    const toml::node* n = node(key);
    if (n == nullptr) return fallback;
    if (!n->is_boolean()) fail(*n, fmt::format("'{}' expected true or false, got {}", key, toml_type_phrase(*n)));
    return *n->value<bool>();
  }

  template <typename E>
  E choice(std::string_view key, E fallback, const std::vector<std::pair<std::string_view, E>>& options) const {
    const toml::node* n = node(key);
    if (n == nullptr) return fallback;
    std::string list;
    for (const auto& [name, value] : options) list += (list.empty() ? "\"" : ", \"") + std::string(name) + "\"";
    if (!n->is_string()) fail(*n, fmt::format("'{}' expected one of {}, got {}", key, list, toml_type_phrase(*n)));
    const std::string text = *n->value<std::string>();
    for (const auto& [name, value] : options)
      if (name == text) return value;
    fail(*n, fmt::format("'{}' expected one of {}, got \"{}\"", key, list, text));
  }

 private:
  const toml::table& table_;
  const std::string& file_;
  std::string what_;
};

constexpr int64_t kMaxMs = int64_t(24) * 3600 * 1000;

Fault read_fault(const toml::table& table, const std::string& file) {
  TableReader r(table, file, "[[device.fault]]");
  r.check_keys({"frame", "kind", "replug_after_ms", "duration_ms", "count"});
  Fault f;
  f.place = place_of(table.source(), file);
  f.frame = size_t(r.integer("frame", 0, 0, INT32_MAX, true));
  const std::string kind = r.string("kind", "", true);
  const auto parsed = fault_kind_from_name(kind);
  if (!parsed)
    r.fail(*r.node("kind"), fmt::format("'kind' expected one of \"unplug\", \"stall\", \"drop\", \"error_buffer\", "
                                        "\"eagain\", \"eio\", got \"{}\"", kind));
  f.kind = *parsed;
  // Keys that mean nothing for this kind are errors, so a typo'd plan does not silently do less.
  const auto only_for = [&](std::string_view key, FaultKind owner) {
    if (r.node(key) != nullptr && f.kind != owner)
      r.fail(*r.node(key), fmt::format("'{}' applies only to kind \"{}\", not \"{}\"", key, fault_kind_name(owner), kind));
  };
  only_for("replug_after_ms", FaultKind::Unplug);
  only_for("duration_ms", FaultKind::Stall);
  if (r.node("count") != nullptr && f.kind != FaultKind::Drop && f.kind != FaultKind::Eagain)
    r.fail(*r.node("count"), fmt::format("'count' applies only to kinds \"drop\" and \"eagain\", not \"{}\"", kind));
  if (f.kind == FaultKind::Unplug && r.node("replug_after_ms") != nullptr)
    f.replug_after_ns = r.integer("replug_after_ms", 0, 0, kMaxMs) * 1000000;
  if (f.kind == FaultKind::Stall) f.duration_ns = r.integer("duration_ms", 0, 1, kMaxMs, true) * 1000000;
  f.count = uint32_t(r.integer("count", 1, 1, 1000000));
  return f;
}

DeviceConfig read_device(const toml::table& table, const std::string& file, const std::filesystem::path& base,
                         size_t index) {
  TableReader r(table, file, "[[device]]");
  r.check_keys({"path", "recording", "card", "bus_info", "formats", "pacing", "timestamps", "timestamp_source",
                "loop", "jpeg_quality", "gain_unity", "fault"});
  DeviceConfig d;
  d.place = place_of(table.source(), file);
  const std::string path = r.string("path", "", true);
  if (path.empty() || path[0] != '/') r.fail(*r.node("path"), fmt::format("'path' expected an absolute path, got \"{}\"", path));
  d.path = normal_device_path(path);
  const std::string recording = r.string("recording", "", true);
  if (recording.empty()) r.fail(*r.node("recording"), "'recording' expected a recording directory, got \"\"");
  d.recording = (base / recording).lexically_normal();
  d.card = r.string("card", d.card);
  d.bus_info = r.string("bus_info", fmt::format("platform:arpipe-standin-{}", index));
  if (const toml::node* n = r.node("formats")) {
    d.formats_place = place_of(n->source(), file);
    const toml::array* array = n->as_array();
    if (array == nullptr) r.fail(*n, fmt::format("'formats' expected an array of strings, got {}", toml_type_phrase(*n)));
    if (array->empty()) r.fail(*n, "'formats' expected at least one format");
    d.formats.clear();
    for (const toml::node& item : *array) {
      if (!item.is_string()) r.fail(item, fmt::format("'formats' expected strings, got {}", toml_type_phrase(item)));
      d.formats.push_back(*item.value<std::string>());
    }
  } else {
    d.formats_place = d.place;
  }
  d.pacing = r.choice<Pacing>("pacing", Pacing::Realtime, {{"realtime", Pacing::Realtime}, {"fast", Pacing::Fast}});
  d.timestamps = r.choice<TimestampBase>("timestamps", TimestampBase::Recorded,
                                         {{"recorded", TimestampBase::Recorded}, {"live", TimestampBase::Live}});
  d.timestamp_source = r.choice<TimestampSource>(
      "timestamp_source", TimestampSource::StartOfExposure,
      {{"soe", TimestampSource::StartOfExposure}, {"eof", TimestampSource::EndOfFrame}});
  d.loop = r.boolean("loop", false);
  d.jpeg_quality = int(r.integer("jpeg_quality", 90, 1, 100));
  d.gain_unity = int(r.integer("gain_unity", 100, 1, 1 << 26));
  if (const toml::node* n = r.node("fault")) {
    const toml::array* array = n->as_array();
    if (array == nullptr || !array->is_array_of_tables())
      r.fail(*n, fmt::format("'fault' expected [[device.fault]] tables, got {}", toml_type_phrase(*n)));
    for (const toml::node& item : *array) d.faults.push_back(read_fault(*item.as_table(), file));
  }
  return d;
}

}  // namespace

std::string normal_device_path(const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_relative()) {
    char cwd[4096];
    if (::getcwd(cwd, sizeof cwd) != nullptr) p = std::filesystem::path(cwd) / p;
  }
  std::string out = p.lexically_normal().string();
  while (out.size() > 1 && out.back() == '/') out.pop_back();
  return out;
}

std::vector<DeviceConfig> load_standin_config(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::string why;
  const auto text = read_text_file(file, why);
  if (!text) throw StandinConfigError(fmt::format("{}:1:1: cannot read the configuration: {}", name, why));
  toml::table root;
  try {
    root = toml::parse(*text, std::string_view(name));
  } catch (const toml::parse_error& e) {
    throw StandinConfigError(fmt::format("{}: TOML syntax error: {}", place_of(e.source(), name), e.description()));
  }
  TableReader top(root, name, "the top level");
  top.check_keys({"device"});
  const toml::node* devices = root.get("device");
  if (devices == nullptr) throw StandinConfigError(fmt::format("{}:1:1: expected at least one [[device]] table", name));
  const toml::array* array = devices->as_array();
  if (array == nullptr || !array->is_array_of_tables())
    top.fail(*devices, fmt::format("'device' expected [[device]] tables, got {}", toml_type_phrase(*devices)));
  const std::filesystem::path base = std::filesystem::absolute(file).parent_path();
  std::vector<DeviceConfig> out;
  std::set<std::string> paths;
  for (const toml::node& item : *array) {
    out.push_back(read_device(*item.as_table(), name, base, out.size()));
    if (!paths.insert(out.back().path).second)
      throw StandinConfigError(fmt::format("{}: path \"{}\" is served by an earlier [[device]] already", out.back().place,
                                           out.back().path));
  }
  return out;
}

}  // namespace arpipe::standin
