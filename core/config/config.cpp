// Config loading with toml++: overrides are merged into the parsed tree, then one schema walk
// checks every key, type and range, so the file and the command line are validated alike.
#include "core/config/config.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>
#include <toml++/toml.h>


#include <algorithm>
#include <cctype>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "core/config/text_file.h"
#include "core/config/toml_type_phrase.h"
#include "core/track/tag_family.h"

namespace arpipe {

namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
constexpr const char* kOverridePrefix = "override '";
// Drivers disagree about what their timestamps mean by a frame or two; an hour is far beyond any
// real offset and keeps every exposure time plus the offset inside int64 nanoseconds.
constexpr int64_t kMaxTimestampOffsetNs = 3'600'000'000'000;

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}


// "file:line:column" for file nodes; overrides have no useful line, so they name themselves.
std::string place_of(const toml::source_region& region, const std::string& fallback) {
  if (!region.path) return fallback;
  const std::string& path = *region.path;
  if (path.rfind(kOverridePrefix, 0) == 0) return path;
  return fmt::format("{}:{}:{}", path, region.begin.line, region.begin.column);
}

std::string format_toml_float(double value) {
  std::string text = fmt::format("{}", value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";  // TOML floats need a point
  return text;
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  return text;
}

// A TOML basic string; control characters are escaped, so the text stays on one line.
std::string toml_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      out += fmt::format("\\u{:04X}", static_cast<unsigned char>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Text for a message: control characters shown as escapes, so a value cannot start a new line.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += "\\t";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
    else out += c;
  }
  return out;
}

// toml++ rejects numbers beyond 64 bits as syntax errors ("'1e400' could not be interpreted as a
// value", "... is not representable in 64 bits"); this says what is wrong with such a number.
std::optional<std::string> out_of_range_number(std::string_view description) {
  const size_t open = description.find('\'');
  const size_t close = open == std::string_view::npos ? open : description.find('\'', open + 1);
  if (close == std::string_view::npos) return std::nullopt;
  const std::string_view token = description.substr(open + 1, close - open - 1);
  if (description.starts_with("Error while parsing floating-point") &&
      description.find("could not be interpreted") != std::string_view::npos)
    return fmt::format("{} is out of range for a 64-bit float (magnitude at most about 1.8e308)", token);
  if (description.find("is not representable in 64 bits") != std::string_view::npos)
    return fmt::format("{} is out of range for a 64-bit integer [-9223372036854775808, 9223372036854775807]", token);
  return std::nullopt;
}

// The 1-based column where the quoted number of a toml++ description starts on line `line`.
std::optional<toml::source_index> number_column(std::string_view text, uint32_t line, std::string_view description) {
  const size_t open = description.find('\'');
  const size_t close = open == std::string_view::npos ? open : description.find('\'', open + 1);
  if (close == std::string_view::npos) return std::nullopt;
  const std::string_view token = description.substr(open + 1, close - open - 1);
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
    const std::string_view content = trim(text.substr(begin, end - begin));
    if (number == line) {
      const size_t equals = content.find('=');
      const std::string key(trim(content.substr(0, equals == std::string_view::npos ? 0 : equals)));
      if (key.empty()) return table;
      return table.empty() ? key : table + "." + key;
    }
    if (content.starts_with("[[")) {
      const size_t close = content.find("]]");
      const std::string name(trim(content.substr(2, close == std::string_view::npos ? 0 : close - 2)));
      table = fmt::format("{}[{}]", name, array_counts[name]++);
    } else if (content.starts_with("[")) {
      const size_t close = content.find(']');
      table = std::string(trim(content.substr(1, close == std::string_view::npos ? 0 : close - 1)));
    }
    if (end == text.size()) break;
    begin = end + 1;
  }
  return table;
}

// ---- The schema walk ----------------------------------------------------------------------------

class ConfigReader {
 public:
  explicit ConfigReader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& expected) const {
    throw ConfigError(fmt::format("{}: '{}' expected {}", place_of(node.source(), source_), key, expected));
  }
  [[noreturn]] void fail_got(const toml::node& node, const std::string& key, const std::string& expected,
                             const std::string& got) const {
    throw ConfigError(fmt::format("{}: '{}' expected {}, got {}", place_of(node.source(), source_), key, expected, got));
  }

  // Throws on the first key (in file order) that is not in `allowed`.
  void check_keys(const toml::table& table, const std::string& prefix, const std::vector<std::string>& allowed,
                  const std::string& where) const {
    const toml::key* first = nullptr;
    const toml::node* first_value = nullptr;
    for (auto&& [key, value] : table) {
      if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
      if (first == nullptr || earlier(region_of(key, value), region_of(*first, *first_value))) {
        first = &key;
        first_value = &value;
      }
    }
    if (first == nullptr) return;
    throw ConfigError(fmt::format("{}: unknown key '{}{}'; allowed keys in {}: {}",
                                  place_of(region_of(*first, *first_value), source_), prefix, first->str(), where,
                                  join(allowed)));
  }

  const toml::table* table(const toml::table& parent, const std::string& prefix, const char* key) const {
    const toml::node* node = parent.get(key);
    if (node == nullptr) return nullptr;
    if (!node->is_table()) fail_got(*node, prefix + key, "a table", std::string(toml_type_phrase(*node)));
    return node->as_table();
  }

  // An array whose elements are all tables ([[name]] or an inline array of inline tables).
  const toml::array* array_of_tables(const toml::table& parent, const std::string& prefix, const char* key) const {
    const toml::node* node = parent.get(key);
    if (node == nullptr) return nullptr;
    if (!node->is_array()) fail_got(*node, prefix + key, "an array of tables", std::string(toml_type_phrase(*node)));
    const toml::array& array = *node->as_array();
    for (size_t i = 0; i < array.size(); ++i)
      if (!array[i].is_table())
        fail_got(array[i], fmt::format("{}{}[{}]", prefix, key, i), "a table", std::string(toml_type_phrase(array[i])));
    return &array;
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, bool& out) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return;
    if (!node->is_boolean()) fail_got(*node, prefix + key, "a boolean (true or false)", std::string(toml_type_phrase(*node)));
    out = node->as_boolean()->get();
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, int64_t& out,
            int64_t min = std::numeric_limits<int64_t>::min(), int64_t max = std::numeric_limits<int64_t>::max()) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return;
    if (!node->is_integer()) fail_got(*node, prefix + key, "an integer", std::string(toml_type_phrase(*node)));
    const int64_t value = node->as_integer()->get();
    if (value < min || value > max) fail_got(*node, prefix + key, range_phrase("an integer", min, max), fmt::format("{}", value));
    out = value;
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, int& out,
            int64_t min = std::numeric_limits<int>::min(), int64_t max = std::numeric_limits<int>::max()) const {
    int64_t value = out;
    read(t, prefix, key, value, std::max<int64_t>(min, std::numeric_limits<int>::min()),
         std::min<int64_t>(max, std::numeric_limits<int>::max()));
    out = static_cast<int>(value);
  }

  // Numbers accept integers too (size_m = 1 means 1.0). `valid` says whether a finite value is in
  // range and `expected` describes the range for the message.
  void read(const toml::table& t, const std::string& prefix, const char* key, double& out,
            const std::function<bool(double)>& valid = nullptr, const std::string& expected = "a number") const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return;
    const double value = number(*node, prefix + key, expected);
    if (valid && !valid(value)) fail_got(*node, prefix + key, expected, format_toml_float(value));
    out = value;
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, std::string& out,
            const std::vector<std::string>& choices = {}) const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return;
    const std::string expected = choices.empty() ? "a string" : "one of " + join(quoted(choices));
    if (!node->is_string()) fail_got(*node, prefix + key, expected, std::string(toml_type_phrase(*node)));
    const std::string& value = node->as_string()->get();
    if (!choices.empty() && std::find(choices.begin(), choices.end(), value) == choices.end())
      fail_got(*node, prefix + key, expected, toml_string(value));
    out = value;
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, std::filesystem::path& out) const {
    std::string text = out.string();
    read(t, prefix, key, text);
    out = text;
  }

  void read(const toml::table& t, const std::string& prefix, const char* key, Vec3& out,
            const std::function<bool(double)>& valid = nullptr, const std::string& item_expected = "numbers") const {
    const toml::node* node = t.get(key);
    if (node == nullptr) return;
    const std::string expected = "an array of 3 " + item_expected + " [x, y, z]";
    if (!node->is_array()) fail_got(*node, prefix + key, expected, std::string(toml_type_phrase(*node)));
    const toml::array& array = *node->as_array();
    if (array.size() != 3) fail_got(*node, prefix + key, expected, fmt::format("{} items", array.size()));
    Vec3 value{};
    for (size_t i = 0; i < 3; ++i) {
      const std::string item_key = fmt::format("{}{}[{}]", prefix, key, i);
      value[i] = number(array[i], item_key, expected);
      if (valid && !valid(value[i])) fail_got(array[i], item_key, expected, format_toml_float(value[i]));
    }
    out = value;
  }

  // Degrees in the file, radians in the struct.
  void read_degrees(const toml::table& t, const std::string& prefix, const char* key, double& out_rad) const {
    if (t.get(key) == nullptr) return;  // keep the default bit for bit
    double degrees = 0;
    read(t, prefix, key, degrees);
    out_rad = degrees * kRadiansPerDegree;
  }

 private:
  static toml::source_region region_of(const toml::key& key, const toml::node& value) {
    return key.source().path ? key.source() : value.source();
  }
  static bool earlier(const toml::source_region& a, const toml::source_region& b) {
    return std::tie(a.begin.line, a.begin.column) < std::tie(b.begin.line, b.begin.column);
  }
  static std::vector<std::string> quoted(const std::vector<std::string>& items) {
    std::vector<std::string> out;
    for (const auto& item : items) out.push_back(toml_string(item));
    return out;
  }
  static std::string range_phrase(const std::string& what, int64_t min, int64_t max) {
    const bool has_min = min != std::numeric_limits<int64_t>::min() && min != std::numeric_limits<int>::min();
    const bool has_max = max != std::numeric_limits<int64_t>::max() && max != std::numeric_limits<int>::max();
    if (has_min && has_max) return fmt::format("{} in [{}, {}]", what, min, max);
    if (has_min) return fmt::format("{} >= {}", what, min);
    if (has_max) return fmt::format("{} <= {}", what, max);
    return what;
  }

  double number(const toml::node& node, const std::string& key, const std::string& expected) const {
    double value;
    if (node.is_integer())
      value = static_cast<double>(node.as_integer()->get());
    else if (node.is_floating_point())
      value = node.as_floating_point()->get();
    else
      fail_got(node, key, expected, std::string(toml_type_phrase(node)));
    if (!std::isfinite(value)) fail_got(node, key, "a finite number", format_toml_float(value));
    return value;
  }

  std::string source_;
};

const auto positive = [](double v) { return v > 0; };
const auto non_negative = [](double v) { return v >= 0; };

void read_source(const ConfigReader& r, const toml::table& t, SourceConfig& out) {
  const std::string p = "source.";
  r.check_keys(t, p,
               {"type", "path", "pacing", "loop", "timestamp_offset_ns", "camera_model", "device", "camera", "role",
                "width", "height", "fps", "pixel_format", "buffers", "exposure_us", "gain", "gain_unity",
                "timestamp_meaning", "readout_ns", "frame_timeout_ms", "reconnect_min_ms", "reconnect_max_ms"},
               "[source]");
  r.read(t, p, "type", out.type, {"replay", "v4l2", "libcamera"});
  r.read(t, p, "path", out.path);
  r.read(t, p, "pacing", out.pacing, {"timestamps", "fast"});
  r.read(t, p, "loop", out.loop);
  r.read(t, p, "timestamp_offset_ns", out.timestamp_offset_ns, -kMaxTimestampOffsetNs, kMaxTimestampOffsetNs);
  r.read(t, p, "camera_model", out.camera_model);
  r.read(t, p, "device", out.device);
  r.read(t, p, "camera", out.camera);
  r.read(t, p, "role", out.role, {"video", "viewfinder", "still", "raw"});
  r.read(t, p, "width", out.width, 0, 16384);
  r.read(t, p, "height", out.height, 0, 16384);
  r.read(t, p, "fps", out.fps, non_negative, "a number >= 0");
  r.read(t, p, "pixel_format", out.pixel_format, {"auto", "YUYV", "NV12", "RGB24", "GREY", "MJPG"});
  r.read(t, p, "buffers", out.buffers, 4, 32);  // fewer than 4 starves the driver while one is being converted
  r.read(t, p, "exposure_us", out.exposure_us, 0, 60'000'000);
  r.read(t, p, "gain", out.gain, non_negative, "a number >= 0");
  r.read(t, p, "gain_unity", out.gain_unity, positive, "a number > 0");
  r.read(t, p, "timestamp_meaning", out.timestamp_meaning, {"auto", "start-of-exposure", "end-of-frame"});
  r.read(t, p, "readout_ns", out.readout_ns, 0, 1'000'000'000);
  r.read(t, p, "frame_timeout_ms", out.frame_timeout_ms, 1, 600'000);
  r.read(t, p, "reconnect_min_ms", out.reconnect_min_ms, 1, 600'000);
  r.read(t, p, "reconnect_max_ms", out.reconnect_max_ms, 1, 3'600'000);
  if (out.reconnect_max_ms < out.reconnect_min_ms) {
    const toml::node* node = t.get("reconnect_max_ms") ? t.get("reconnect_max_ms") : t.get("reconnect_min_ms");
    r.fail_got(*node, p + "reconnect_max_ms", fmt::format("at least reconnect_min_ms ({})", out.reconnect_min_ms),
               fmt::format("{}", out.reconnect_max_ms));
  }
}

void read_track(const ConfigReader& r, const toml::table& t, TrackConfig& out) {
  const std::string p = "track.";
  r.check_keys(t, p,
               {"enabled", "family", "bundle", "quad_decimate", "quad_sigma", "threads", "max_hamming",
                "min_decision_margin", "ambiguity_ratio", "refine_corners", "max_predicted_frames"},
               "[track]");
  r.read(t, p, "enabled", out.enabled);
  std::vector<std::string> families;
  for (const auto family : tag_family_names()) families.emplace_back(family);
  r.read(t, p, "family", out.family, families);
  r.read(t, p, "quad_decimate", out.quad_decimate, [](double v) { return v >= 1; }, "a number >= 1");
  r.read(t, p, "quad_sigma", out.quad_sigma);  // negative sharpens in libapriltag, so any value goes
  r.read(t, p, "threads", out.threads, 1, 64);
  r.read(t, p, "max_hamming", out.max_hamming, 0, 3);  // libapriltag corrects at most 3 bits
  r.read(t, p, "min_decision_margin", out.min_decision_margin, non_negative, "a number >= 0");
  r.read(t, p, "ambiguity_ratio", out.ambiguity_ratio, [](double v) { return v >= 1; }, "a number >= 1");
  r.read(t, p, "refine_corners", out.refine_corners);
  // A second of prediction at 30 fps is already far beyond what constant velocity predicts well.
  r.read(t, p, "max_predicted_frames", out.max_predicted_frames, 0, 30);

  if (const toml::array* bundle = r.array_of_tables(t, p, "bundle")) {
    const int64_t code_count = create_tag_family(out.family)->ncodes;
    out.bundle.clear();
    std::set<int> ids;
    for (size_t i = 0; i < bundle->size(); ++i) {
      const toml::table& tag_table = *(*bundle)[i].as_table();
      const std::string tp = fmt::format("track.bundle[{}].", i);
      r.check_keys(tag_table, tp, {"id", "size_m", "center_m", "yaw_deg"}, "[[track.bundle]]");
      BundleTag tag;
      r.read(tag_table, tp, "id", tag.id, 0, code_count - 1);
      r.read(tag_table, tp, "size_m", tag.size_m, positive, "a number > 0");
      r.read(tag_table, tp, "center_m", tag.center_m);
      r.read_degrees(tag_table, tp, "yaw_deg", tag.yaw_rad);
      if (!ids.insert(tag.id).second) {
        const toml::node* id = tag_table.get("id");
        r.fail_got(id != nullptr ? *id : (*bundle)[i], tp + "id", "an id not used by another tag of the bundle",
                   fmt::format("{} a second time", tag.id));
      }
      out.bundle.push_back(tag);
    }
    if (out.enabled && out.bundle.empty())
      r.fail(*t.get("bundle"), p + "bundle", "at least one tag while tracking is enabled");
  }
  // Without a bundle key the default bundle (tag 0) stays, and tag 0 exists in every family.
}

void read_motion(const ConfigReader& r, const toml::table& t, MotionConfig& out) {
  const std::string p = "motion.";
  r.check_keys(t, p, {"enabled", "latency_frames", "default_exposure_ms"}, "[motion]");
  r.read(t, p, "enabled", out.enabled);
  // Only the previous-current (0) or current-next (1) segment is implemented; holding more
  // frames would add latency without a better estimate of one exposure.
  r.read(t, p, "latency_frames", out.latency_frames);
  if (out.latency_frames != 0 && out.latency_frames != 1)
    r.fail_got(*t.get("latency_frames"), p + "latency_frames",
               "0 (extrapolate, no delay) or 1 (hold each frame back by one and interpolate)",
               fmt::format("{}", out.latency_frames));
  if (const toml::node* node = t.get("default_exposure_ms")) {
    double ms = 0;
    // Up to one second: longer than any frame interval a tracking camera runs at. The stage caps it
    // at each frame's own interval, and frames with their own exposure never use it.
    r.read(t, p, "default_exposure_ms", ms, [](double v) { return v > 0 && v <= 1000; }, "a number in (0, 1000] (ms)");
    out.default_exposure_ns = std::llround(ms * 1e6);
    if (out.default_exposure_ns <= 0) r.fail_got(*node, p + "default_exposure_ms", "at least 1 ns", format_toml_float(ms));
  }
}

void read_shadows(const ConfigReader& r, const toml::table& t, ShadowConfig& out) {
  const std::string p = "render.shadows.";
  r.check_keys(t, p,
               {"method", "map_size", "pcf_kernel", "vsm_blur", "vsm_bleed_reduction", "depth_bias_texels",
                "receiver_height_m", "light_angular_diameter_deg"},
               "[render.shadows]");
  r.read(t, p, "method", out.method, {"off", "hard", "pcf", "pcss", "vsm", "vsm-packed"});
  r.read(t, p, "map_size", out.map_size);
  if (out.map_size != 256 && out.map_size != 512 && out.map_size != 1024 && out.map_size != 2048 && out.map_size != 4096)
    r.fail_got(*t.get("map_size"), p + "map_size", "one of 256, 512, 1024, 2048, 4096", fmt::format("{}", out.map_size));
  r.read(t, p, "pcf_kernel", out.pcf_kernel, 1, 16);
  r.read(t, p, "vsm_blur", out.vsm_blur, 1, 31);
  if (out.vsm_blur % 2 == 0)
    r.fail_got(*t.get("vsm_blur"), p + "vsm_blur", "an odd integer in [1, 31] (taps across a centred kernel)",
               fmt::format("{}", out.vsm_blur));
  r.read(t, p, "vsm_bleed_reduction", out.vsm_bleed_reduction, [](double v) { return v >= 0 && v < 0.95; },
         "a number in [0, 0.95)");
  r.read(t, p, "depth_bias_texels", out.depth_bias_texels, [](double v) { return v >= 0 && v <= 100; },
         "a number in [0, 100] (texels)");
  r.read(t, p, "receiver_height_m", out.receiver_height_m);
  r.read(t, p, "light_angular_diameter_deg", out.light_angular_diameter_deg,
         [](double v) { return v >= 0 && v < 90; }, "a number in [0, 90) (degrees)");
}

bool is_camera_response(const std::string& text) {
  if (text == "srgb" || text == "linear") return true;
  if (text.rfind("gamma:", 0) != 0) return false;
  char* end = nullptr;
  const double g = std::strtod(text.c_str() + 6, &end);
  return end != text.c_str() + 6 && *end == '\0' && std::isfinite(g) && g > 0 && g <= 10;
}

void read_light(const ConfigReader& r, const toml::table& t, LightConfig& out) {
  const std::string p = "light.";
  r.check_keys(t, p, {"source", "response", "smoothing_s", "ground_albedo", "probe", "sun", "environment"}, "[light]");
  r.read(t, p, "source", out.source, {"fixed", "probe", "sun", "environment"});
  r.read(t, p, "response", out.response);
  if (!is_camera_response(out.response))
    r.fail_got(*t.get("response"), p + "response", "\"srgb\", \"linear\" or \"gamma:<g>\" with 0 < g <= 10",
               toml_string(out.response));
  r.read(t, p, "smoothing_s", out.smoothing_s, [](double v) { return v >= 0 && v <= 60; }, "a number in [0, 60] (s)");
  r.read(t, p, "ground_albedo", out.ground_albedo, [](double v) { return v > 0 && v <= 1; }, "numbers in (0, 1]");
  if (const toml::table* probe = r.table(t, p, "probe")) {
    const std::string pp = "light.probe.";
    r.check_keys(*probe, pp, {"kind", "center_m", "radius_m", "reflectance", "method", "max_lights", "light_distance_m"},
                   "[light.probe]");
    r.read(*probe, pp, "kind", out.probe.kind, {"mirror", "diffuse"});
    r.read(*probe, pp, "center_m", out.probe.center_m);
    r.read(*probe, pp, "radius_m", out.probe.radius_m, [](double v) { return v > 0 && v <= 10; }, "a number in (0, 10] (m)");
    r.read(*probe, pp, "reflectance", out.probe.reflectance, [](double v) { return v > 0 && v <= 1; },
           "a number in (0, 1]");
    r.read(*probe, pp, "method", out.probe.method, {"auto", "environment", "fit", "seed-image", "seed-sphere"});
    r.read(*probe, pp, "max_lights", out.probe.max_lights, 1, 4);
    r.read(*probe, pp, "light_distance_m", out.probe.light_distance_m, [](double v) { return v >= 0 && v <= 1e6; },
           "a number in [0, 1e6] (m; 0: infinitely far)");
  }
  if (const toml::table* sun = r.table(t, p, "sun")) {
    const std::string sp = "light.sun.";
    r.check_keys(*sun, sp,
                 {"latitude_deg", "longitude_deg", "altitude_m", "time", "heading_deg", "declination_deg",
                  "pressure_mbar", "temperature_c", "direct_fraction"},
                 "[light.sun]");
    r.read(*sun, sp, "latitude_deg", out.sun.latitude_deg, [](double v) { return v >= -90 && v <= 90; },
           "a latitude in [-90, 90] (degrees, north positive)");
    r.read(*sun, sp, "longitude_deg", out.sun.longitude_deg, [](double v) { return v >= -180 && v <= 180; },
           "a longitude in [-180, 180] (degrees, east positive)");
    r.read(*sun, sp, "altitude_m", out.sun.altitude_m, [](double v) { return v >= -500 && v <= 20000; },
           "a number in [-500, 20000] (m)");
    r.read(*sun, sp, "time", out.sun.time);
    r.read(*sun, sp, "heading_deg", out.sun.heading_deg, [](double v) { return v >= -360 && v <= 360; },
           "a number in [-360, 360] (degrees)");
    r.read(*sun, sp, "declination_deg", out.sun.declination_deg, [](double v) { return v >= -180 && v <= 180; },
           "a number in [-180, 180] (degrees, east positive)");
    r.read(*sun, sp, "pressure_mbar", out.sun.pressure_mbar, [](double v) { return v > 0 && v <= 5000; },
           "a number in (0, 5000] (mbar)");
    r.read(*sun, sp, "temperature_c", out.sun.temperature_c, [](double v) { return v > -273 && v <= 6000; },
           "a number in (-273, 6000] (degrees Celsius)");
    r.read(*sun, sp, "direct_fraction", out.sun.direct_fraction, [](double v) { return v >= 0 && v <= 1; },
           "a number in [0, 1]");
  }
  if (const toml::table* environment = r.table(t, p, "environment")) {
    const std::string ep = "light.environment.";
    r.check_keys(*environment, ep, {"file", "layout", "yaw_deg", "scale", "window"}, "[light.environment]");
    r.read(*environment, ep, "file", out.environment.file);
    r.read(*environment, ep, "layout", out.environment.layout, {"angular", "mirror-ball", "equirect", "cube-cross"});
    r.read_degrees(*environment, ep, "yaw_deg", out.environment.yaw_rad);
    r.read(*environment, ep, "scale", out.environment.scale, [](double v) { return v > 0 && v <= 1e12; },
           "a number in (0, 1e12]");
    r.read(*environment, ep, "window", out.environment.window, {"none", "hanning", "lanczos"});
  }
  if (out.source == "environment" && out.environment.file.empty())
    r.fail(*t.get("source"), p + "source", "light.environment.file to be set when the source is \"environment\"");
}

void read_render(const ConfigReader& r, const toml::table& t, RenderConfig& out) {
  const std::string p = "render.";
  r.check_keys(t, p,
               {"enabled", "objects", "light_direction", "light_distance_m", "light_color", "ambient", "msaa_samples", "egl_platform",
                "lens", "lens_canvas_scale", "rolling_shutter", "max_predicted_uncertainty_deg", "blur", "shadows", "prt"},
               "[render]");
  r.read(t, p, "enabled", out.enabled);
  if (const toml::array* objects = r.array_of_tables(t, p, "objects")) {
    out.objects.clear();
    for (size_t i = 0; i < objects->size(); ++i) {
      const toml::table& object_table = *(*objects)[i].as_table();
      const std::string op = fmt::format("render.objects[{}].", i);
      r.check_keys(object_table, op, {"mesh", "position_m", "yaw_deg", "scale", "color", "prt", "specular"}, "[[render.objects]]");
      SceneObject object;
      r.read(object_table, op, "mesh", object.mesh);
      if (object.mesh.empty()) r.fail(*object_table.get("mesh"), op + "mesh", "\"builtin:cube\", \"builtin:pyramid\" or a glTF file");
      r.read(object_table, op, "position_m", object.position_m);
      r.read_degrees(object_table, op, "yaw_deg", object.yaw_rad);
      r.read(object_table, op, "scale", object.scale, positive, "a number > 0");
      r.read(object_table, op, "color", object.color, non_negative, "numbers >= 0");
      r.read(object_table, op, "prt", object.prt, {"off", "unshadowed", "shadowed", "interreflected"});
      r.read(object_table, op, "specular", object.specular, [](double v) { return v >= 0 && v <= 1; },
             "a number in [0, 1]");
      out.objects.push_back(object);
    }
  }
  r.read(t, p, "light_direction", out.light_direction);
  const double length = norm(out.light_direction);
  if (length == 0) r.fail(*t.get("light_direction"), p + "light_direction", "a non-zero direction");
  // A vector already of unit length is kept bit for bit, so printing and reading a config is exact.
  if (std::abs(length - 1.0) > 1e-12) out.light_direction = normalized(out.light_direction);
  r.read(t, p, "light_distance_m", out.light_distance_m, [](double v) { return v >= 0 && v <= 1e6; },
         "a number in [0, 1e6] (m; 0: infinitely far)");
  r.read(t, p, "light_color", out.light_color, non_negative, "numbers >= 0");
  r.read(t, p, "ambient", out.ambient, non_negative, "numbers >= 0");
  r.read(t, p, "msaa_samples", out.msaa_samples);
  if (out.msaa_samples != 0 && out.msaa_samples != 1 && out.msaa_samples != 2 && out.msaa_samples != 4)
    r.fail_got(*t.get("msaa_samples"), p + "msaa_samples", "one of 0, 1, 2, 4", fmt::format("{}", out.msaa_samples));
  r.read(t, p, "egl_platform", out.egl_platform, {"auto", "surfaceless", "device"});
  r.read(t, p, "lens", out.lens, {"map", "vertex", "undistort"});
  r.read(t, p, "lens_canvas_scale", out.lens_canvas_scale, [](double v) { return v >= 1 && v <= 4; },
         "a number in [1, 4]");
  r.read(t, p, "rolling_shutter", out.rolling_shutter);
  r.read(t, p, "max_predicted_uncertainty_deg", out.max_predicted_uncertainty_deg,
         [](double v) { return v >= 0 && v <= 180; }, "a number in [0, 180] (degrees)");
  if (const toml::table* blur = r.table(t, p, "blur")) {
    const std::string bp = "render.blur.";
    r.check_keys(*blur, bp, {"method", "samples", "min_motion_px"}, "[render.blur]");
    r.read(*blur, bp, "method", out.blur.method, {"off", "accumulate", "seed", "velocity"});
    // 1024: far beyond what converges (bench blur's reference uses 256); the seed method caps at 50.
    r.read(*blur, bp, "samples", out.blur.samples, 0, 1024);
    r.read(*blur, bp, "min_motion_px", out.blur.min_motion_px, [](double v) { return v >= 0 && v <= 1000; },
           "a number in [0, 1000] (pixels)");
  }
  if (const toml::table* shadows = r.table(t, p, "shadows")) read_shadows(r, *shadows, out.shadows);
  if (const toml::table* prt = r.table(t, p, "prt")) {
    const std::string pp = "render.prt.";
    r.check_keys(*prt, pp, {"samples", "bands", "cache_dir"}, "[render.prt]");
    r.read(*prt, pp, "samples", out.prt.samples, 2, 256);
    r.read(*prt, pp, "bands", out.prt.bands, 3, 8);
    r.read(*prt, pp, "cache_dir", out.prt.cache_dir);
  }
}

void read_sinks(const ConfigReader& r, const toml::table& t, SinksConfig& out) {
  r.check_keys(t, "sinks.", {"png", "y4m", "recording", "results"}, "[sinks]");
  if (const toml::table* png = r.table(t, "sinks.", "png")) {
    r.check_keys(*png, "sinks.png.", {"enabled", "dir", "every"}, "[sinks.png]");
    r.read(*png, "sinks.png.", "enabled", out.png.enabled);
    r.read(*png, "sinks.png.", "dir", out.png.dir);
    r.read(*png, "sinks.png.", "every", out.png.every, 1);
  }
  if (const toml::table* y4m = r.table(t, "sinks.", "y4m")) {
    r.check_keys(*y4m, "sinks.y4m.", {"enabled", "path"}, "[sinks.y4m]");
    r.read(*y4m, "sinks.y4m.", "enabled", out.y4m.enabled);
    r.read(*y4m, "sinks.y4m.", "path", out.y4m.path);
  }
  if (const toml::table* recording = r.table(t, "sinks.", "recording")) {
    r.check_keys(*recording, "sinks.recording.", {"enabled", "path"}, "[sinks.recording]");
    r.read(*recording, "sinks.recording.", "enabled", out.recording.enabled);
    r.read(*recording, "sinks.recording.", "path", out.recording.path);
  }
  if (const toml::table* results = r.table(t, "sinks.", "results")) {
    r.check_keys(*results, "sinks.results.", {"enabled", "path"}, "[sinks.results]");
    r.read(*results, "sinks.results.", "enabled", out.results.enabled);
    r.read(*results, "sinks.results.", "path", out.results.path);
  }
}

void read_pipeline(const ConfigReader& r, const toml::table& t, PipelineConfig& out) {
  const std::string p = "pipeline.";
  r.check_keys(t, p, {"queue_depth", "max_frames", "log_level"}, "[pipeline]");
  r.read(t, p, "queue_depth", out.queue_depth, 1);
  r.read(t, p, "max_frames", out.max_frames, 0);
  r.read(t, p, "log_level", out.log_level, {"error", "warning", "info", "debug"});
}

Config read_config(const toml::table& root, const std::string& source) {
  const ConfigReader r(source);
  Config config;
  config.file = source;
  r.check_keys(root, "", {"source", "track", "motion", "light", "render", "sinks", "pipeline"}, "the top level");
  if (const toml::table* t = r.table(root, "", "source")) read_source(r, *t, config.source);
  if (const toml::table* t = r.table(root, "", "track")) read_track(r, *t, config.track);
  if (const toml::table* t = r.table(root, "", "motion")) read_motion(r, *t, config.motion);
  if (const toml::table* t = r.table(root, "", "light")) read_light(r, *t, config.light);
  if (const toml::table* t = r.table(root, "", "render")) read_render(r, *t, config.render);
  if (const toml::table* t = r.table(root, "", "sinks")) read_sinks(r, *t, config.sinks);
  if (const toml::table* t = r.table(root, "", "pipeline")) read_pipeline(r, *t, config.pipeline);
  return config;
}

// ---- Overrides ---------------------------------------------------------------------------------

[[noreturn]] void override_error(const std::string& label, const std::string& what) {
  throw ConfigError(fmt::format("{}: {}", label, what));
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

void apply_override(toml::table& root, const std::string& assignment) {
  const std::string label = fmt::format("{}{}'", kOverridePrefix, printable(assignment));
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos) override_error(label, "expected section.key=value");
  const std::string_view key = trim(std::string_view(assignment).substr(0, equals));
  const std::string_view value = trim(std::string_view(assignment).substr(equals + 1));
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
    if (const auto range = out_of_range_number(e.description()))
      override_error(label, fmt::format("'{}' is out of range: {}", key, *range));
    if (!looks_like_bare_word(value))
      override_error(label, fmt::format("the value is not valid TOML ({}); quote strings", e.description()));
    parsed = toml::parse(fmt::format("{} = {}", key, toml_string(value)), std::string_view(label));
  }
  if (!is_single_assignment(parsed, key))
    override_error(label, fmt::format("the value of '{}' is not exactly one TOML value", key));
  merge_override(root, parsed, "", label);
}

Config parse_table(toml::table root, const std::string& source_name, const std::vector<std::string>& overrides) {
  for (const std::string& assignment : overrides) apply_override(root, assignment);
  return read_config(root, source_name);
}

}  // namespace

Config parse_config(const std::string& text, const std::string& source_name, const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    if (const auto range = out_of_range_number(e.description())) {
      // toml++ places the error after the number; the message points at the number itself.
      toml::source_region where = e.source();
      where.begin.column = number_column(text, where.begin.line, e.description()).value_or(where.begin.column);
      throw ConfigError(fmt::format("{}: '{}' is out of range: {}", place_of(where, source_name),
                                    key_on_line(text, where.begin.line), *range));
    }
    throw ConfigError(fmt::format("{}: TOML syntax error: {}", place_of(e.source(), source_name), e.description()));
  }
  return parse_table(std::move(root), source_name, overrides);
}

Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw ConfigError(fmt::format("{}: cannot read config: {}", path.string(), why));
  Config config = parse_config(*text, path.string(), overrides);
  config.file = path;
  return config;
}

std::string default_config_toml() {
  const Config d;
  const auto f = [](double v) { return format_toml_float(v); };
  const auto vec = [&](const Vec3& v) { return fmt::format("[{}, {}, {}]", f(v[0]), f(v[1]), f(v[2])); };
  const auto b = [](bool v) { return std::string(v ? "true" : "false"); };
  const auto s = [](const std::string& text) { return toml_string(text); };
  std::string out;
  // One "key = value" line, its comment aligned in a column when it fits.
  const auto entry = [&out](std::string_view key, const std::string& value, std::string_view comment = {}) {
    const std::string assignment = fmt::format("{} = {}", key, value);
    if (comment.empty())
      out += assignment + "\n";
    else
      out += fmt::format("{:<32}# {}\n", assignment + " ", comment);
  };
  out += "# arpiped configuration: every key is optional and shows its default; unknown keys are errors.\n";
  out += "# Units: metres, nanoseconds, and degrees for angles (the code works in radians).\n";

  out += "\n[source]\n";
  entry("type", s(d.source.type), "\"replay\", \"v4l2\" or \"libcamera\"");
  entry("path", s(d.source.path.string()), "replay: the recording directory");
  entry("pacing", s(d.source.pacing), "replay: \"timestamps\" (real time) or \"fast\"");
  entry("loop", b(d.source.loop), "replay: start again at the end");
  entry("timestamp_offset_ns", fmt::format("{}", d.source.timestamp_offset_ns),
        "added to every exposure start of this camera; within +-1 hour (3600000000000)");
  entry("camera_model", s(d.source.camera_model.string()),
        "a .cameramodel to use instead of the recording's (live: needed to track)");
  entry("device", s(d.source.device), "v4l2: /dev/videoN or a /dev/v4l/by-id or by-path link");
  entry("camera", s(d.source.camera), "libcamera: a camera id or index (\"\": the first)");
  entry("role", s(d.source.role), "libcamera stream role: video, viewfinder, still, raw");
  entry("width", fmt::format("{}", d.source.width), "live: 0 = the camera's first size");
  entry("height", fmt::format("{}", d.source.height));
  entry("fps", format_toml_float(d.source.fps), "live: 0 = the camera's default rate");
  entry("pixel_format", s(d.source.pixel_format), "YUYV, NV12, RGB24, GREY, MJPG (decoded to RGB24) or auto");
  entry("buffers", fmt::format("{}", d.source.buffers), "capture buffers, 4 to 32");
  entry("exposure_us", fmt::format("{}", d.source.exposure_us), "manual exposure; 0 = auto exposure");
  entry("gain", format_toml_float(d.source.gain), "manual analogue gain (1 = unity); 0 = auto");
  entry("gain_unity", format_toml_float(d.source.gain_unity), "v4l2: the gain control value that means gain 1");
  entry("timestamp_meaning", s(d.source.timestamp_meaning),
        "v4l2: auto (the driver's flag), start-of-exposure or end-of-frame");
  entry("readout_ns", fmt::format("{}", d.source.readout_ns), "rolling-shutter readout time; 0 = global shutter");
  entry("frame_timeout_ms", fmt::format("{}", d.source.frame_timeout_ms), "a frame later than this is a timeout");
  entry("reconnect_min_ms", fmt::format("{}", d.source.reconnect_min_ms), "first retry after the camera went away");
  entry("reconnect_max_ms", fmt::format("{}", d.source.reconnect_max_ms), "retries back off up to this");

  out += "\n[track]\n";
  entry("enabled", b(d.track.enabled));
  std::vector<std::string> families;
  for (const auto family : tag_family_names()) families.emplace_back(family);
  entry("family", s(d.track.family), "one of " + join(families));
  entry("quad_decimate", f(d.track.quad_decimate), ">= 1: find quads in an image this many times smaller");
  entry("quad_sigma", f(d.track.quad_sigma), "blur before finding quads (negative sharpens)");
  entry("threads", fmt::format("{}", d.track.threads), "detector threads, 1..64");
  entry("max_hamming", fmt::format("{}", d.track.max_hamming), "bit errors corrected, 0..3");
  entry("min_decision_margin", f(d.track.min_decision_margin), "weaker detections are ignored");
  entry("ambiguity_ratio", f(d.track.ambiguity_ratio), ">= 1: IPPE's two poses closer than this error ratio are ambiguous");
  entry("refine_corners", b(d.track.refine_corners), "re-fit the tag borders in linear light (libapriltag's corners sit ~0.2 px inside)");
  entry("max_predicted_frames", fmt::format("{}", d.track.max_predicted_frames),
        "0..30: frames without a detection whose pose is predicted at constant velocity (0: none)");
  out += "\n# The anchor: one [[track.bundle]] per tag, placed in the world (anchor) frame, lying in z = 0.\n";
  for (const BundleTag& tag : d.track.bundle) {
    out += "[[track.bundle]]\n";
    entry("id", fmt::format("{}", tag.id), "unique, and within the family");
    entry("size_m", f(tag.size_m), "> 0: edge of the black square (AprilTag's tag size)");
    entry("center_m", vec(tag.center_m), "tag centre in the world frame");
    entry("yaw_deg", f(tag.yaw_rad / kRadiansPerDegree), "turn of the tag's x axis about world z");
  }

  out += "\n[motion]                       # the camera's poses over each exposure (needs tracking)\n";
  entry("enabled", b(d.motion.enabled));
  entry("latency_frames", fmt::format("{}", d.motion.latency_frames),
        "0: extrapolate at constant velocity; 1: hold a frame back and interpolate");
  entry("default_exposure_ms", f(double(d.motion.default_exposure_ns) * 1e-6),
        "(0, 1000]: for frames without an exposure time; capped at the frame interval");

  out += "\n[light]                        # where the light comes from\n";
  entry("source", s(d.light.source),
        "\"fixed\" (render.light_*), \"probe\" (a probe sphere in view), \"sun\" (place and time) or \"environment\" (an HDR probe file)");
  entry("response", s(d.light.response), "camera response: \"srgb\", \"linear\" or \"gamma:<g>\"");
  entry("smoothing_s", f(d.light.smoothing_s), "[0, 60]: time constant of the temporal smoothing");
  entry("ground_albedo", vec(d.light.ground_albedo),
        "(0, 1]: of the real ground, whose brightness sets the sun's level and a clipped lamp's");
  out += "\n[light.probe]                  # a light probe sphere beside the anchor\n";
  entry("kind", s(d.light.probe.kind), "\"mirror\" or \"diffuse\"");
  entry("center_m", vec(d.light.probe.center_m), "world frame");
  entry("radius_m", f(d.light.probe.radius_m), "(0, 10]");
  entry("reflectance", f(d.light.probe.reflectance), "(0, 1]: mirror reflectance, or the diffuse sphere's albedo");
  entry("method", s(d.light.probe.method),
        "\"auto\", \"environment\", \"fit\", \"seed-image\" or \"seed-sphere\"");
  entry("max_lights", fmt::format("{}", d.light.probe.max_lights), "1..4 dominant lights");
  entry("light_distance_m", f(d.light.probe.light_distance_m), "0: lights infinitely far; > 0: the key lamp's distance from the probe");
  out += "\n[light.sun]                    # the sun from place and time (NREL SPA)\n";
  entry("latitude_deg", f(d.light.sun.latitude_deg), "[-90, 90], north positive");
  entry("longitude_deg", f(d.light.sun.longitude_deg), "[-180, 180], east positive");
  entry("altitude_m", f(d.light.sun.altitude_m));
  entry("time", s(d.light.sun.time), "\"now\" (system UTC clock) or an ISO 8601 instant for the first frame");
  entry("heading_deg", f(d.light.sun.heading_deg), "bearing of the anchor's +y axis from true north, clockwise");
  entry("declination_deg", f(d.light.sun.declination_deg), "magnetic declination, east positive, for a compass heading");
  entry("pressure_mbar", f(d.light.sun.pressure_mbar), "for refraction");
  entry("temperature_c", f(d.light.sun.temperature_c), "for refraction");
  entry("direct_fraction", f(d.light.sun.direct_fraction), "[0, 1]: the sun's share of the light on the ground");
  out += "\n[light.environment]            # an HDR light probe file as the whole light\n";
  entry("file", s(d.light.environment.file.string()), "Radiance .hdr or OpenEXR .exr; required with source = \"environment\"");
  entry("layout", s(d.light.environment.layout), "\"angular\", \"mirror-ball\", \"equirect\" or \"cube-cross\"");
  entry("yaw_deg", f(d.light.environment.yaw_rad / kRadiansPerDegree), "turn of the probe about world z (probe up = world z)");
  entry("scale", f(d.light.environment.scale), "(0, 1e12]: the file's radiance units to scene-linear units");
  entry("window", s(d.light.environment.window), "\"none\", \"hanning\" or \"lanczos\": SH windowing against ringing");

  out += "\n[render]\n";
  entry("enabled", b(d.render.enabled));
  entry("light_direction", vec(d.render.light_direction), "world frame, towards the light; normalised on load");
  entry("light_distance_m", f(d.render.light_distance_m), "0: infinitely far; > 0: a lamp that far along light_direction");
  entry("light_color", vec(d.render.light_color), "linear RGB, >= 0");
  entry("ambient", vec(d.render.ambient), "linear RGB, >= 0");
  entry("msaa_samples", fmt::format("{}", d.render.msaa_samples), "0, 1, 2 or 4");
  entry("egl_platform", s(d.render.egl_platform), "\"auto\", \"surfaceless\" or \"device\"");
  out += "# lens: how the virtual layer matches the real lens.\n"
         "#   \"map\": draw with the lens's pinhole core on an enlarged canvas, warp through a per-pixel map\n"
         "#          built once with mrcal (any lens mrcal can unproject, rays up to 75 degrees off axis)\n"
         "#   \"vertex\": distort per vertex (PINHOLE, OPENCV4/5/8 only; straight edges stay straight)\n"
         "#   \"undistort\": undistort the camera frame to the pinhole core instead and draw pinhole: the\n"
         "#          output is an undistorted picture whose camera model is that pinhole core\n";
  entry("lens", s(d.render.lens), "\"map\", \"vertex\" or \"undistort\"");
  entry("lens_canvas_scale", f(d.render.lens_canvas_scale),
        "\"map\": canvas pixels per core pixel, [1, 4]; finer edges, cost grows with its square");
  entry("rolling_shutter", b(d.render.rolling_shutter),
        "draw each row with its own exposure's pose when the readout time is non-zero");
  entry("max_predicted_uncertainty_deg", f(d.render.max_predicted_uncertainty_deg),
        "[0, 180]: a predicted pose less certain than this is not drawn");
  out += "\n[render.blur]                  # motion blur of the virtual layer over each exposure\n";
  entry("method", s(d.render.blur.method),
        "\"off\", \"accumulate\" (N renders: the reference), \"seed\" (2 renders + affine warps), \"velocity\" (fastest)");
  entry("samples", fmt::format("{}", d.render.blur.samples), "0..1024; 0: from the frame's image motion");
  entry("min_motion_px", f(d.render.blur.min_motion_px), "frames with less image motion are drawn sharp");
  out += "\n[render.shadows]               # shadows of the virtual objects, on themselves and on the real ground\n";
  entry("method", s(d.render.shadows.method),
        "\"off\", \"hard\", \"pcf\", \"pcss\" (penumbra from the light's size), \"vsm\" or \"vsm-packed\" (RGBA8)");
  entry("map_size", fmt::format("{}", d.render.shadows.map_size), "texels across: 256, 512, 1024, 2048 or 4096");
  entry("pcf_kernel", fmt::format("{}", d.render.shadows.pcf_kernel), "pcf: k x k taps, 1..16");
  entry("vsm_blur", fmt::format("{}", d.render.shadows.vsm_blur), "vsm: Gaussian taps across, odd, 1..31");
  entry("vsm_bleed_reduction", f(d.render.shadows.vsm_bleed_reduction), "vsm: [0, 0.95), cuts light bleeding");
  entry("depth_bias_texels", f(d.render.shadows.depth_bias_texels), "self-shadowing bias, [0, 100] texels");
  entry("receiver_height_m", f(d.render.shadows.receiver_height_m), "world z of the real ground");
  entry("light_angular_diameter_deg", f(d.render.shadows.light_angular_diameter_deg),
        "[0, 90): size of the fixed light (pcss); estimates bring their own");
  out += "\n[render.prt]                   # precomputed radiance transfer, baked once per mesh (arpipe bake)\n";
  entry("samples", fmt::format("{}", d.render.prt.samples), "2..256 per axis: samples^2 directions per vertex");
  entry("bands", fmt::format("{}", d.render.prt.bands), "3..8 SH bands baked (the shader uses 3)");
  entry("cache_dir", s(d.render.prt.cache_dir.string()), "\"\": $XDG_CACHE_HOME/arpipe/prt, else ~/.cache/arpipe/prt");
  out += "\n# Virtual objects: one [[render.objects]] each, placed in the world (anchor) frame.\n";
  for (const SceneObject& object : d.render.objects) {
    out += "[[render.objects]]\n";
    entry("mesh", s(object.mesh), "\"builtin:cube\", \"builtin:pyramid\" or a glTF 2.0 file");
    entry("position_m", vec(object.position_m));
    entry("yaw_deg", f(object.yaw_rad / kRadiansPerDegree), "about world z");
    entry("scale", f(object.scale), "> 0");
    entry("color", vec(object.color), "linear base colour of builtin meshes, >= 0");
    entry("prt", s(object.prt), "environment light: \"off\", \"unshadowed\", \"shadowed\" or \"interreflected\"");
    entry("specular", f(object.specular), "[0, 1]: glossy reflection of the environment, added untinted");
  }

  out += "\n[sinks.png]\n";
  entry("enabled", b(d.sinks.png.enabled));
  entry("dir", s(d.sinks.png.dir.string()));
  entry("every", fmt::format("{}", d.sinks.png.every), ">= 1: write every Nth frame");
  out += "\n[sinks.y4m]\n";
  entry("enabled", b(d.sinks.y4m.enabled));
  entry("path", s(d.sinks.y4m.path.string()));
  out += "\n[sinks.recording]\n";
  entry("enabled", b(d.sinks.recording.enabled));
  entry("path", s(d.sinks.recording.path.string()));
  out += "\n[sinks.results]                # per-frame pose, tracking state and timings as JSON lines\n";
  entry("enabled", b(d.sinks.results.enabled));
  entry("path", s(d.sinks.results.path.string()));

  out += "\n[pipeline]\n";
  entry("queue_depth", fmt::format("{}", d.pipeline.queue_depth), ">= 1: frames between threads");
  entry("max_frames", fmt::format("{}", d.pipeline.max_frames), "stop after this many frames; 0 = no limit");
  entry("log_level", s(d.pipeline.log_level), "\"error\", \"warning\", \"info\" or \"debug\"");
  return out;
}

}  // namespace arpipe
