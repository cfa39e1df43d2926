#include "standin_config.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <unistd.h>

#include <set>

#include "core/config/text_file.h"
#include "core/config/toml_section.h"

namespace arpipe::standin {

namespace {

constexpr int64_t kMaxMs = int64_t(24) * 3600 * 1000;

// Keys without a default: an absent one is "found nothing", placed at its table.
void require(const TomlSection& s, std::string_view key, const std::string& expected) {
  if (!s.has(key)) s.fail(key, expected, "nothing");
}

// The table's own place ("file:line:column"), for messages about the device or fault as a whole.
std::string table_place(const TomlSection& s) { return toml_place(s.table().source(), s.source_name()); }

// A non-empty array of format names; messages place a bad name at the array.
std::vector<OfferedFormatName> read_formats(const TomlSection& s, std::vector<OfferedFormatName> fallback) {
  const toml::node* n = s.node("formats");
  if (n == nullptr) return fallback;
  const std::string expected =
      "an array of formats, each one of " + choice_list<OfferedFormatName>(kOfferedFormatNames);
  if (!n->is_array()) s.fail("formats", expected, std::string(toml_type_phrase(*n)));
  if (n->as_array()->empty()) s.fail("formats", expected, "an empty array");
  std::vector<OfferedFormatName> out;
  for (const toml::node& item : *n->as_array()) {
    if (!item.is_string()) s.fail("formats", expected, std::string(toml_type_phrase(item)));
    const auto format = choice_value<OfferedFormatName>(kOfferedFormatNames, item.as_string()->get());
    if (!format) s.fail("formats", expected, toml_quoted(item.as_string()->get()));
    out.push_back(*format);
  }
  return out;
}

Fault read_fault(const TomlSection& s) {
  Fault f;
  f.place = table_place(s);
  const IntRange frames{0, INT32_MAX};
  require(s, "frame", frames.phrase());
  f.frame = static_cast<size_t>(s.integer("frame", 0, frames));
  require(s, "kind", "one of " + choice_list<FaultKind>(kFaultKindNames));
  f.kind = s.choice("kind", FaultKind::Drop, kFaultKindNames);
  const std::string_view kind = choice_name<FaultKind>(kFaultKindNames, f.kind);
  // Keys that mean nothing for this kind are errors, so a typo'd plan does not silently do less.
  const auto only_for = [&](std::string_view key, FaultKind owner) {
    if (s.has(key) && f.kind != owner)
      s.fail_with(key, fmt::format("applies only to kind \"{}\", not \"{}\"",
                                   choice_name<FaultKind>(kFaultKindNames, owner), kind));
  };
  only_for("replug_after_ms", FaultKind::Unplug);
  only_for("duration_ms", FaultKind::Stall);
  if (s.has("count") && f.kind != FaultKind::Drop && f.kind != FaultKind::Eagain)
    s.fail_with("count", fmt::format("applies only to kinds \"drop\" and \"eagain\", not \"{}\"", kind));
  if (f.kind == FaultKind::Unplug && s.has("replug_after_ms"))
    f.replug_after_ns = s.integer("replug_after_ms", 0, IntRange{0, kMaxMs}) * 1000000;
  if (f.kind == FaultKind::Stall) {
    const IntRange stall{1, kMaxMs};
    require(s, "duration_ms", stall.phrase());
    f.duration_ns = s.integer("duration_ms", 0, stall) * 1000000;
  }
  f.count = s.integer_as<uint32_t>("count", 1, IntRange{1, 1000000});
  return f;
}

DeviceConfig read_device(const TomlSection& s, const std::filesystem::path& base, size_t index) {
  DeviceConfig d;
  d.place = table_place(s);
  require(s, "path", "an absolute path");
  const std::string path = s.string("path", "");
  if (path.empty() || path[0] != '/') s.fail("path", "an absolute path", toml_quoted(path));
  d.path = normal_device_path(path);
  require(s, "recording", "a recording directory");
  const std::string recording = s.string("recording", "");
  if (recording.empty()) s.fail("recording", "a recording directory", toml_quoted(recording));
  d.recording = (base / recording).lexically_normal();
  d.card = s.string("card", d.card);
  d.bus_info = s.string("bus_info", fmt::format("platform:arpipe-standin-{}", index));
  d.formats_place = s.place("formats");
  d.formats = read_formats(s, d.formats);
  d.buffer_type = s.choice("buffer_type", d.buffer_type, kBufferTypeNames);
  if (d.buffer_type == BufferType::Single)
    for (const OfferedFormatName f : d.formats)
      if (multi_planar_only(f))
        s.fail_with("formats", fmt::format("format \"{}\" has split planes: it needs buffer_type = \"mplane\"",
                                           choice_name<OfferedFormatName>(kOfferedFormatNames, f)));
  d.pacing = s.choice("pacing", d.pacing, kPacingNames);
  d.timestamps = s.choice("timestamps", d.timestamps, kTimestampBaseNames);
  d.timestamp_source = s.choice("timestamp_source", d.timestamp_source, kTimestampSourceNames);
  d.loop = s.boolean("loop", d.loop);
  d.jpeg_quality = s.integer_as<int>("jpeg_quality", d.jpeg_quality, IntRange{1, 100});
  d.gain_unity = s.integer_as<int>("gain_unity", d.gain_unity, IntRange{1, 1 << 26});
  for (const TomlSection& fault : s.sections("fault"))
    d.faults.push_back(read_fault(fault));
  return d;
}

// An absolute device path under `key` (required).
std::string read_device_path(const TomlSection& s, std::string_view key) {
  require(s, key, "an absolute path");
  const std::string path = s.string(key, "");
  if (path.empty() || path[0] != '/') s.fail(key, "an absolute path", toml_quoted(path));
  return normal_device_path(path);
}

LoopbackStall read_loopback_fault(const TomlSection& s) {
  LoopbackStall f;
  f.place = table_place(s);
  const IntRange frames{0, INT32_MAX};
  require(s, "frame", frames.phrase());
  f.frame = uint64_t(s.integer("frame", 0, frames));
  require(s, "kind", "\"stall\"");
  if (s.string("kind", "") != "stall") s.fail("kind", "\"stall\"", toml_quoted(s.string("kind", "")));
  const IntRange stall{1, kMaxMs};
  require(s, "duration_ms", stall.phrase());
  f.duration_ns = s.integer("duration_ms", 0, stall) * 1000000;
  return f;
}

LoopbackConfig read_loopback(const TomlSection& s, const std::filesystem::path& base, size_t index) {
  LoopbackConfig l;
  l.place = table_place(s);
  l.output = read_device_path(s, "output");
  l.capture = read_device_path(s, "capture");
  if (l.capture == l.output) s.fail("capture", "a path other than the output's", toml_quoted(l.capture));
  require(s, "spool", "a directory");
  const std::string spool = s.string("spool", "");
  if (spool.empty()) s.fail("spool", "a directory", toml_quoted(spool));
  l.spool = (base / spool).lexically_normal();
  l.card = s.string("card", l.card);
  l.bus_info = s.string("bus_info", fmt::format("platform:arpipe-loopback-{}", index));
  l.formats = read_formats(s, l.formats);
  for (const OfferedFormatName f : l.formats)
    if (f != OfferedFormatName::Yuyv && f != OfferedFormatName::Rgb24 && f != OfferedFormatName::Grey &&
        f != OfferedFormatName::Nv12)
      s.fail("formats", "an array of raw pixel formats, each one of \"YUYV\", \"RGB24\", \"GREY\", \"NV12\"",
             toml_quoted(std::string(choice_name<OfferedFormatName>(kOfferedFormatNames, f))));
  for (size_t i = 0; i < l.formats.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (l.formats[i] == l.formats[j])
        s.fail("formats", "each format once",
               toml_quoted(std::string(choice_name<OfferedFormatName>(kOfferedFormatNames, l.formats[i]))) + " twice");
  // 16384 keeps a frame (at most 3 bytes a pixel) under 1 GiB, so sizes fit V4L2's 32-bit fields.
  l.max_width = s.integer_as<int>("max_width", l.max_width, IntRange{2, 16384});
  l.max_height = s.integer_as<int>("max_height", l.max_height, IntRange{2, 16384});
  l.max_spool_bytes = s.integer("max_spool_mib", l.max_spool_bytes >> 20, IntRange{1, int64_t(1) << 24}) << 20;
  for (const TomlSection& fault : s.sections("fault", 10000)) l.stalls.push_back(read_loopback_fault(fault));
  return l;
}

StandinConfig read_config(const TomlSection& file, const std::filesystem::path& base) {
  const std::vector<TomlSection> devices = file.sections("device");
  const std::vector<TomlSection> loopbacks = file.sections("loopback");
  if (devices.empty() && loopbacks.empty())
    file.fail("device", "at least one [[device]] or [[loopback]] table", file.has("device") ? "none" : "nothing");
  StandinConfig out;
  // Every served path once, whichever table serves it.
  std::set<std::string> paths;
  for (const TomlSection& device : devices) {
    out.devices.push_back(read_device(device, base, out.devices.size()));
    if (!paths.insert(out.devices.back().path).second)
      device.fail("path", "a path no earlier [[device]] serves", toml_quoted(out.devices.back().path));
  }
  std::set<std::filesystem::path> spools;
  for (const TomlSection& loopback : loopbacks) {
    out.loopbacks.push_back(read_loopback(loopback, base, out.loopbacks.size()));
    const LoopbackConfig& l = out.loopbacks.back();
    for (const auto& [key, path] : {std::pair{"output", l.output}, std::pair{"capture", l.capture}})
      if (!paths.insert(path).second)
        loopback.fail(key, "a path no earlier [[device]] or [[loopback]] serves", toml_quoted(path));
    if (!spools.insert(l.spool).second)
      loopback.fail("spool", "a directory no earlier [[loopback]] uses", toml_quoted(l.spool.string()));
  }
  file.reject_stray_keys();
  return out;
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

StandinConfig load_standin_config(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::string why;
  const auto text = read_text_file(file, why);
  if (!text) throw StandinConfigError(fmt::format("{}:1:1: cannot read the configuration: {}", name, why));
  try {
    const toml::table root = parse_toml(*text, name);
    return read_config(TomlSection(root, name), std::filesystem::absolute(file).parent_path());
  } catch (const TomlInputError& e) {
    throw StandinConfigError(e.what());
  }
}

}  // namespace arpipe::standin
