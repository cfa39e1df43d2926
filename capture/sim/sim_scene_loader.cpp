// Scene files with toml++: one walk over the tree reads every key with its default, checks its
// type and range, rejects unknown keys, and checks that the scene as a whole can be simulated.
#include "capture/sim/sim_scene_loader.h"

#include <apriltag/apriltag.h>
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <system_error>

#include <unistd.h>

#include "capture/sim/sim_textures.h"
#include "capture/sim/simulator.h"
#include "core/config/regular_file.h"
#include "core/config/toml_stray_key.h"
#include "core/config/text_file.h"
#include "core/config/toml_type_phrase.h"
#include "core/image/image_header.h"
#include "core/scene/asset_error.h"
#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "core/track/tag_family.h"

namespace arpipe::sim {

namespace {

namespace fs = std::filesystem;

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
constexpr double kNsPerMs = 1e6;
// Counts a scene file may declare: far above any real scene, low enough that a small file cannot
// make the simulator build thousands of Embree objects or walk millions of keyframes.
constexpr size_t kMaxObjects = 1000;
constexpr size_t kMaxLights = 100;
constexpr size_t kMaxKeyframes = 100000;
constexpr size_t kMaxListNumbers = 10000;  // exposure cycles, intrinsics (a splined model has a few thousand)
// `up` closer than this (sine of the angle) to the viewing direction leaves the image's roll
// undefined for practical purposes (0.06 degrees).
constexpr double kMinUpAngleSine = 1e-3;

std::string join(const std::vector<std::string_view>& items, std::string_view separator = ", ") {
  std::string out;
  for (const auto item : items) out += fmt::format("{}{}", out.empty() ? "" : separator, item);
  return out;
}

std::string in_quotes(std::string_view text) { return fmt::format("\"{}\"", text); }

std::string type_phrase(const toml::node& node) { return std::string(toml_type_phrase(node)); }


std::string show(const Vec3& v) { return fmt::format("[{}, {}, {}]", v[0], v[1], v[2]); }

// A numeric range with the phrase that describes it in messages.
struct Range {
  std::function<bool(double)> ok;
  std::string phrase;
};
const Range kAnyNumber{nullptr, "a number"};
const Range kPositive{[](double v) { return v > 0; }, "a number > 0"};
const Range kNonNegative{[](double v) { return v >= 0; }, "a number >= 0"};
const Range kUnitInterval{[](double v) { return v >= 0 && v <= 1; }, "a number in [0, 1]"};

// Places in the file and the error messages that name them.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  // "file:line:col" of a node; nodes made by the parser without a place (implicit tables) fall
  // back to the start of the file so the message keeps its shape.
  std::string place(const toml::source_region& region) const {
    if (region.begin.line == 0) return fmt::format("{}:1:1", source_);
    return fmt::format("{}:{}:{}", source_, region.begin.line, region.begin.column);
  }
  [[noreturn]] void fail(const toml::source_region& at, const std::string& key, const std::string& what) const {
    throw SceneError(fmt::format("{}: {}: {}", place(at), key, what));
  }
  [[noreturn]] void syntax_error(const toml::parse_error& e) const {
    throw SceneError(fmt::format("{}: TOML syntax error: {}", place(e.source()), e.description()));
  }
  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

// One table of the scene file and its dotted name ("camera.sensor", "object[2]"): reads keys with
// their defaults, checks types and ranges, and names the key in every message.
class Section {
 public:
  Section(const Reader& reader, const toml::table& table, std::string name, const fs::path& base_dir)
      : r_(reader), t_(table), name_(std::move(name)), base_dir_(base_dir) {}

  std::string key(std::string_view k) const { return name_.empty() ? std::string(k) : fmt::format("{}.{}", name_, k); }
  const toml::node* node(std::string_view k) const { return t_.get(k); }
  bool has(std::string_view k) const { return t_.contains(k); }
  // Where a message about key k points: the key's value, else the table itself.
  const toml::source_region& at(std::string_view k) const {
    const toml::node* n = node(k);
    return n != nullptr ? n->source() : t_.source();
  }

  [[noreturn]] void fail(std::string_view k, const std::string& what) const { r_.fail(at(k), key(k), what); }
  [[noreturn]] void fail(const toml::node& n, const std::string& dotted, const std::string& expected,
                         const std::string& found) const {
    r_.fail(n.source(), dotted, fmt::format("expected {}, found {}", expected, found));
  }
  [[noreturn]] void fail(std::string_view k, const std::string& expected, const std::string& found) const {
    r_.fail(at(k), key(k), fmt::format("expected {}, found {}", expected, found));
  }

  // Throws on the first key (in file order) that is not in `allowed`.
  void allow(const std::vector<std::string_view>& allowed) const {
    const auto stray = first_stray_key(t_, allowed);
    if (stray) r_.fail(stray->where, key(stray->name), fmt::format("unknown key; expected one of {}", join(allowed)));
  }
  // A key that makes no sense with the rest of the table.
  void forbid(std::string_view k, const std::string& why) const {
    if (has(k)) fail(k, fmt::format("not allowed here: {}", why));
  }

  std::optional<Section> table(std::string_view k) const {
    const toml::node* n = node(k);
    if (n == nullptr) return std::nullopt;
    if (!n->is_table()) fail(k, "a table", type_phrase(*n));
    return Section(r_, *n->as_table(), key(k), base_dir_);
  }
  // [[k]] entries (or an inline array of inline tables), named "k[0]", "k[1]"...
  // At most max_count of them (the limit is in the message).
  std::vector<Section> tables(std::string_view k, size_t max_count) const {
    std::vector<Section> out;
    const toml::node* n = node(k);
    if (n == nullptr) return out;
    const std::string expected = fmt::format("an array of tables ([[{}]])", k);
    if (!n->is_array()) fail(k, expected, type_phrase(*n));
    const toml::array& array = *n->as_array();
    if (array.size() > max_count)
      fail(k, fmt::format("at most {} [[{}]] tables", max_count, k), fmt::format("{}", array.size()));
    for (size_t i = 0; i < array.size(); ++i) {
      const std::string item = fmt::format("{}[{}]", key(k), i);
      if (!array[i].is_table()) fail(array[i], item, "a table", type_phrase(array[i]));
      out.emplace_back(r_, *array[i].as_table(), item, base_dir_);
    }
    return out;
  }

  bool boolean(std::string_view k, bool fallback) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    if (!n->is_boolean()) fail(k, "true or false", type_phrase(*n));
    return n->as_boolean()->get();
  }

  int64_t integer(std::string_view k, int64_t fallback, int64_t min, int64_t max) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    const std::string expected = max == std::numeric_limits<int64_t>::max()
                                     ? fmt::format("an integer >= {}", min)
                                     : fmt::format("an integer in [{}, {}]", min, max);
    if (!n->is_integer()) fail(k, expected, type_phrase(*n));
    const int64_t value = n->as_integer()->get();
    if (value < min || value > max) fail(k, expected, fmt::format("{}", value));
    return value;
  }

  // Integers count as numbers (size_m = 1 means 1.0).
  double number(std::string_view k, double fallback, const Range& range = kAnyNumber) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    return number_of(*n, key(k), range);
  }

  double degrees(std::string_view k, double fallback_rad, const Range& range = kAnyNumber) const {
    if (!has(k)) return fallback_rad;  // the default stays bit for bit
    return number(k, 0, range) * kRadiansPerDegree;
  }

  // Milliseconds in the file, nanoseconds inside.
  int64_t milliseconds(std::string_view k, int64_t fallback_ns, const Range& range = kAnyNumber) const {
    if (!has(k)) return fallback_ns;
    const double ms = number(k, 0, range);
    // Times add up (start, offset, exposure, readout) in int64 ns, which holds +-9.2e12 ms.
    if (std::abs(ms) > kMaxAbsMs)
      fail(k, fmt::format("{}, within +-{:g} ms", range.phrase, kMaxAbsMs), fmt::format("{}", ms));
    return ms_to_ns(ms);
  }

  std::string string(std::string_view k, const std::string& fallback,
                     const std::vector<std::string_view>& choices = {}) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    std::vector<std::string> shown;
    for (const auto c : choices) shown.push_back(in_quotes(c));
    const std::string expected =
        choices.empty() ? "a string" : fmt::format("one of {}", join({shown.begin(), shown.end()}));
    if (!n->is_string()) fail(k, expected, type_phrase(*n));
    const std::string& value = n->as_string()->get();
    if (!choices.empty() && std::find(choices.begin(), choices.end(), value) == choices.end())
      fail(k, expected, in_quotes(value));
    return value;
  }

  std::vector<double> numbers(std::string_view k, std::vector<double> fallback, const Range& range = kAnyNumber,
                              size_t max_count = kMaxListNumbers) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    const std::string expected = fmt::format("an array of numbers ({} each)", range.phrase);
    if (!n->is_array()) fail(k, expected, type_phrase(*n));
    std::vector<double> out;
    const toml::array& array = *n->as_array();
    if (array.size() > max_count)
      fail(k, fmt::format("an array of at most {} numbers", max_count), fmt::format("{} numbers", array.size()));
    for (size_t i = 0; i < array.size(); ++i)
      out.push_back(number_of(array[i], fmt::format("{}[{}]", key(k), i), range));
    return out;
  }

  Vec3 vec3(std::string_view k, const Vec3& fallback, const Range& range = kAnyNumber) const {
    const toml::node* n = node(k);
    if (n == nullptr) return fallback;
    const std::string expected = fmt::format("an array of 3 numbers ({} each)", range.phrase);
    if (!n->is_array()) fail(k, expected, type_phrase(*n));
    const toml::array& array = *n->as_array();
    if (array.size() != 3) fail(k, expected, fmt::format("{} items", array.size()));
    Vec3 out{};
    for (size_t i = 0; i < 3; ++i) out[i] = number_of(array[i], fmt::format("{}[{}]", key(k), i), range);
    return out;
  }

  // A file named relative to the scene file's directory; it must exist and be readable.
  fs::path file(std::string_view k, std::string_view what) const {
    const std::string text = string(k, "");
    if (text.empty()) fail(k, fmt::format("the name of {}", what), has(k) ? "an empty string" : "nothing");
    fs::path path(text);
    if (path.is_relative() && !base_dir_.empty()) path = base_dir_ / path;
    path = path.lexically_normal();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec && ec != std::errc::no_such_file_or_directory)  // a symlink loop, no permission on a directory
      fail(k, fmt::format("expected {}, found \"{}\" ({}): {}", what, text, path.string(), ec.message()));
    if (!fs::exists(status))
      fail(k, fmt::format("expected {}, found \"{}\" ({}): no such file", what, text, path.string()));
    if (fs::is_directory(status))
      fail(k, fmt::format("expected {}, found \"{}\" ({}): a directory", what, text, path.string()));
    // Regular files only (no FIFO to block on, no device), and not empty.
    try {
      const int fd = open_regular_file(path, what);
      char first = 0;
      const ssize_t n = ::read(fd, &first, 1);
      ::close(fd);
      if (n != 1)
        fail(k, fmt::format("expected {}, found \"{}\" ({}): cannot read it: {}", what, text, path.string(),
                            n == 0 ? "it is empty" : std::strerror(errno)));
    } catch (const FileAccessError& e) {
      fail(k, fmt::format("expected {}, found \"{}\" ({}): {}", what, text, path.string(), e.reason()));
    }
    return path;
  }

  static constexpr double kMaxAbsMs = 1e12;  // 31 years
  static int64_t ms_to_ns(double ms) { return std::llround(std::clamp(ms, -kMaxAbsMs, kMaxAbsMs) * kNsPerMs); }

 private:
  double number_of(const toml::node& n, const std::string& dotted, const Range& range) const {
    double value = 0;
    if (n.is_integer())
      value = static_cast<double>(n.as_integer()->get());
    else if (n.is_floating_point())
      value = n.as_floating_point()->get();
    else
      fail(n, dotted, range.phrase, type_phrase(n));
    if (!std::isfinite(value))
      fail(n, dotted, fmt::format("a finite number ({})", range.phrase), fmt::format("{}", value));
    if (range.ok && !range.ok(value)) fail(n, dotted, range.phrase, fmt::format("{}", value));
    return value;
  }

  const Reader& r_;
  const toml::table& t_;
  std::string name_;
  fs::path base_dir_;
};

// ---- [world] -----------------------------------------------------------------------------------

Vec3 read_world(const Section& s) {
  s.allow({"north"});
  const Vec3 north = s.vec3("north", {0, 1, 0});
  const double length = norm(north);
  if (length == 0) s.fail("north", "a non-zero horizontal direction [x, y, 0]", show(north));
  if (std::abs(north[2]) > 1e-12 * length)
    s.fail("north", "a horizontal direction [x, y, 0] (world z is up)", fmt::format("{} (z is not 0)", show(north)));
  const Vec3 horizontal{north[0], north[1], 0};
  return std::abs(length - 1) <= 1e-15 ? horizontal : normalized(horizontal);
}

// ---- [camera] ----------------------------------------------------------------------------------

CameraModel read_camera_model(const Section& s) {
  const std::vector<std::string_view> inline_keys{"lensmodel", "intrinsics", "width", "height"};
  if (s.has("model")) {
    for (const auto k : inline_keys)
      s.forbid(k, "the lens comes from camera.model; give either model or lensmodel/intrinsics/width/height");
    const fs::path path = s.file("model", "an mrcal .cameramodel file");
    try {
      return CameraModel::load(path);
    } catch (const CameraModelError& e) {
      s.fail("model", fmt::format("expected a valid mrcal .cameramodel file, found one that is not ({}): {}",
                                  path.string(), e.what()));
    }
  }
  const int width = static_cast<int>(s.integer("width", 640, 1, 65535));
  const int height = static_cast<int>(s.integer("height", 480, 1, 65535));
  const std::string lensmodel = s.string("lensmodel", "LENSMODEL_PINHOLE");
  if (lensmodel != "LENSMODEL_PINHOLE" && !s.has("intrinsics"))
    s.fail("intrinsics", fmt::format("the intrinsics of {} (fx, fy, cx, cy, then its distortion)", lensmodel),
           "nothing");
  const std::vector<double> intrinsics = s.numbers("intrinsics", {500, 500, (width - 1) / 2.0, (height - 1) / 2.0});
  try {
    return CameraModel(lensmodel, intrinsics, width, height);
  } catch (const CameraModelError& e) {
    const bool bad_name = std::string_view(e.what()).find("unknown lens model") != std::string_view::npos;
    s.fail(bad_name || !s.has("intrinsics") ? "lensmodel" : "intrinsics",
           fmt::format("expected a valid mrcal lens model and intrinsics, found: {}", e.what()));
  }
}

std::string read_response(const Section& s) {
  const std::string response = s.string("response", "srgb");
  if (response == "srgb" || response == "linear") return response;
  const std::string expected = "\"srgb\", \"linear\" or \"gamma:<g>\" with g > 0";
  if (response.rfind("gamma:", 0) != 0) s.fail("response", expected, in_quotes(response));
  const std::string number = response.substr(6);
  char* end = nullptr;
  const double gamma = std::strtod(number.c_str(), &end);
  if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(gamma) || gamma <= 0)
    s.fail("response", expected, in_quotes(response));
  return response;
}

SimCamera read_camera(const Section& s) {
  s.allow({"model", "lensmodel", "intrinsics", "width", "height", "pixel_format", "fps", "exposure_ms", "analogue_gain",
           "digital_gain", "readout_ms", "timestamp", "timestamp_offset_ms", "first_exposure_start_ms", "auto_exposure",
           "sensor"});
  SimCamera camera;
  if (s.has("model") || s.has("lensmodel") || s.has("intrinsics") || s.has("width") || s.has("height"))
    camera.model = read_camera_model(s);

  const std::string format = s.string("pixel_format", "YUYV", {"GREY", "RGB24", "YUYV", "NV12"});
  camera.pixel_format = *pixel_format_from_name(format);
  if (const auto problem = check_image_size(camera.pixel_format, camera.model.width(), camera.model.height())) {
    const std::string_view k = s.has("pixel_format") ? "pixel_format" : s.has("model") ? "model" : "width";
    s.fail(k, fmt::format("expected an image size that {} can hold, found {}x{}: {}", format, camera.model.width(),
                          camera.model.height(), *problem));
  }
  if (camera.model.width() > kMaxFrameSide || camera.model.height() > kMaxFrameSide ||
      int64_t{camera.model.width()} * camera.model.height() > kMaxFramePixels) {
    const std::string_view k = s.has("model") ? "model" : camera.model.width() > kMaxFrameSide || !s.has("height") ? "width" : "height";
    s.fail(k, fmt::format("expected a simulated frame of at most {} pixels a side and {} pixels in all (rendering "
                          "holds about 80 bytes a pixel), found {}x{}",
                          kMaxFrameSide, kMaxFramePixels, camera.model.width(), camera.model.height()));
  }

  camera.fps =
      s.number("fps", camera.fps, {[](double v) { return v > 0 && v <= 1e6; }, "a frame rate in (0, 1000000]"});
  const int64_t interval_ns = std::llround(1e9 / camera.fps);
  const std::string interval =
      fmt::format("the frame interval {:.6g} ms (1 / fps {})", interval_ns / kNsPerMs, camera.fps);
  const auto check_within_interval = [&](const toml::node& n, const std::string& dotted, int64_t ns) {
    if (ns <= 0) s.fail(n, dotted, "an exposure of at least 1 ns", fmt::format("{} ns after rounding", ns));
    if (ns > interval_ns)
      s.fail(n, dotted, fmt::format("no more than {}", interval), fmt::format("{:.6g} ms", ns / kNsPerMs));
  };

  if (const toml::node* n = s.node("exposure_ms")) {
    camera.exposure_ns.clear();
    if (n->is_array()) {
      const std::vector<double> list = s.numbers("exposure_ms", {}, kPositive);
      if (list.empty()) s.fail("exposure_ms", "at least one exposure time", "an empty array");
      for (size_t i = 0; i < list.size(); ++i) {
        camera.exposure_ns.push_back(Section::ms_to_ns(list[i]));
        check_within_interval(*n->as_array()->get(i), fmt::format("{}[{}]", s.key("exposure_ms"), i),
                              camera.exposure_ns.back());
      }
    } else {
      if (!n->is_number())
        s.fail("exposure_ms", "a number > 0 or an array of them (cycled per frame)", type_phrase(*n));
      camera.exposure_ns.push_back(s.milliseconds("exposure_ms", 0, kPositive));
      check_within_interval(*n, s.key("exposure_ms"), camera.exposure_ns.back());
    }
  }
  if (camera.exposure_ns.front() > interval_ns)  // the default exposure at a high frame rate
    s.fail("fps",
           fmt::format("a frame interval of at least the exposure {:.6g} ms (camera.exposure_ms)",
                       camera.exposure_ns.front() / kNsPerMs),
           fmt::format("{} frames/s ({})", camera.fps, interval));

  camera.analogue_gain = s.number("analogue_gain", camera.analogue_gain, kPositive);
  camera.digital_gain = s.number("digital_gain", camera.digital_gain, kPositive);
  camera.readout_ns = s.milliseconds("readout_ms", camera.readout_ns, kNonNegative);
  if (camera.readout_ns > interval_ns)
    s.fail("readout_ms", fmt::format("no more than {}", interval),
           fmt::format("{:.6g} ms", camera.readout_ns / kNsPerMs));

  const std::string timestamp =
      s.string("timestamp", "start_of_exposure", {"start_of_exposure", "end_of_frame", "sensor"});
  timestamp_meaning_from_name(timestamp, camera.timestamp_meaning);
  camera.timestamp_offset_ns = s.milliseconds("timestamp_offset_ms", camera.timestamp_offset_ns);
  camera.first_exposure_start_ns =
      s.milliseconds("first_exposure_start_ms", camera.first_exposure_start_ns, kNonNegative);

  if (const auto ae = s.table("auto_exposure")) {
    ae->allow({"enabled", "target", "min_exposure_ms", "max_gain"});
    SimAutoExposure& out = camera.auto_exposure;
    out.enabled = ae->boolean("enabled", out.enabled);
    out.target = ae->number("target", out.target, {[](double v) { return v > 0 && v <= 1; }, "a number in (0, 1]"});
    out.min_exposure_ns = ae->milliseconds("min_exposure_ms", out.min_exposure_ns, kPositive);
    if (const toml::node* n = ae->node("min_exposure_ms"))
      check_within_interval(*n, ae->key("min_exposure_ms"), out.min_exposure_ns);
    out.max_gain = ae->number("max_gain", out.max_gain, {[](double v) { return v >= 1; }, "a number >= 1"});
  }

  if (const auto sensor = s.table("sensor")) {
    sensor->allow({"sensitivity", "full_well_electrons", "read_noise_electrons", "noise", "response"});
    SimSensor& out = camera.sensor;
    out.sensitivity = sensor->number("sensitivity", out.sensitivity, kPositive);
    out.full_well_electrons = sensor->number("full_well_electrons", out.full_well_electrons, kPositive);
    out.read_noise_electrons = sensor->number("read_noise_electrons", out.read_noise_electrons, kNonNegative);
    out.noise = sensor->boolean("noise", out.noise);
    out.response = read_response(*sensor);
  }
  return camera;
}

// ---- [render] ----------------------------------------------------------------------------------

SimRender read_render(const Section& s) {
  s.allow({"samples_per_pixel", "frames", "seed", "write_linear"});
  SimRender render;
  render.samples_per_pixel = static_cast<int>(s.integer("samples_per_pixel", render.samples_per_pixel, 1, 65536));
  if (samples_per_axis(render.samples_per_pixel) == 0)
    s.fail("samples_per_pixel", "a perfect square (1, 4, 9, 16, ...: a sqrt x sqrt grid in the pixel)",
           fmt::format("{}", render.samples_per_pixel));
  render.frames = static_cast<int>(s.integer("frames", render.frames, 1, std::numeric_limits<int>::max()));
  render.seed = static_cast<uint64_t>(
      s.integer("seed", static_cast<int64_t>(render.seed), 0, std::numeric_limits<int64_t>::max()));
  render.write_linear = s.boolean("write_linear", render.write_linear);
  return render;
}

// ---- [trajectory] ------------------------------------------------------------------------------

// A camera south of the origin, 0.5 m away, looking at it 53 degrees down: the anchor tag upright.
const SimKeyframe kDefaultKeyframe{0.0, {0.0, -0.3, 0.4}, {0, 0, 0}, {0, 0, 1}, 0.0};

SimKeyframe read_keyframe(const Section& s, const SimKeyframe* previous) {
  s.allow({"time_s", "position", "look_at", "up", "roll_deg"});
  SimKeyframe k = kDefaultKeyframe;
  k.time_s = s.number("time_s", k.time_s);
  if (previous != nullptr && !(k.time_s > previous->time_s))
    s.fail("time_s",
           fmt::format("a time after the previous keyframe's {} s (times must strictly increase)", previous->time_s),
           fmt::format("{} s", k.time_s));
  k.position = s.vec3("position", k.position);
  k.look_at = s.vec3("look_at", k.look_at);
  k.up = s.vec3("up", k.up);
  k.roll_rad = s.degrees("roll_deg", k.roll_rad);
  const Vec3 view = k.look_at - k.position;
  if (norm(view) == 0)
    s.fail("look_at", fmt::format("a point other than the camera position {}", show(k.position)), show(k.look_at));
  if (norm(k.up) == 0) s.fail("up", "a non-zero direction", show(k.up));
  if (norm(cross(normalized(k.up), normalized(view))) < kMinUpAngleSine)
    s.fail("up", fmt::format("a direction not parallel to the viewing direction {} (look_at - position)", show(view)),
           fmt::format("{}{}, parallel to it", show(k.up), s.has("up") ? "" : " (the default)"));
  return k;
}

SimRandomPath read_random_path(const Section& s) {
  s.allow({"target", "min_distance_m", "max_distance_m", "min_elevation_deg", "max_elevation_deg", "max_blur_px"});
  SimRandomPath path;
  path.target = s.vec3("target", path.target);
  path.min_distance_m = s.number("min_distance_m", path.min_distance_m, kPositive);
  path.max_distance_m = s.number("max_distance_m", path.max_distance_m, kPositive);
  if (path.max_distance_m < path.min_distance_m)
    s.fail(s.has("max_distance_m") ? "max_distance_m" : "min_distance_m", "min_distance_m <= max_distance_m",
           fmt::format("min {} m > max {} m", path.min_distance_m, path.max_distance_m));
  const Range elevation{[](double v) { return v > 0 && v <= 90; }, "an elevation in (0, 90] degrees"};
  path.min_elevation_rad = s.degrees("min_elevation_deg", path.min_elevation_rad, elevation);
  path.max_elevation_rad = s.degrees("max_elevation_deg", path.max_elevation_rad, elevation);
  if (path.max_elevation_rad < path.min_elevation_rad)
    s.fail(s.has("max_elevation_deg") ? "max_elevation_deg" : "min_elevation_deg",
           "min_elevation_deg <= max_elevation_deg",
           fmt::format("min {:.6g} deg > max {:.6g} deg", path.min_elevation_rad / kRadiansPerDegree,
                       path.max_elevation_rad / kRadiansPerDegree));
  path.max_blur_px =
      s.number("max_blur_px", path.max_blur_px, {[](double v) { return v >= 0 && v <= 200; }, "a blur in [0, 200] px"});
  return path;
}

SimTrajectory read_trajectory(const std::optional<Section>& s) {
  SimTrajectory trajectory;
  if (!s) {
    trajectory.keyframes.push_back(kDefaultKeyframe);
    return trajectory;
  }
  s->allow({"kind", "keyframe", "random"});
  const std::string kind = s->string("kind", "keyframes", {"keyframes", "random"});
  if (kind == "random") {
    trajectory.kind = SimTrajectory::Kind::Random;
    s->forbid("keyframe", "kind = \"random\" takes its path from [trajectory.random]");
    if (const auto random = s->table("random")) trajectory.random = read_random_path(*random);
    return trajectory;
  }
  s->forbid("random", "[trajectory.random] needs kind = \"random\"");
  for (const Section& k : s->tables("keyframe", kMaxKeyframes))
    trajectory.keyframes.push_back(
        read_keyframe(k, trajectory.keyframes.empty() ? nullptr : &trajectory.keyframes.back()));
  if (trajectory.keyframes.empty())
    s->fail("keyframe", "at least one [[trajectory.keyframe]] (one: a still camera)",
            s->has("keyframe") ? "none" : "nothing");
  return trajectory;
}

// ---- [[object]] --------------------------------------------------------------------------------

// Fills the texture and, for two-tone textures, the plane's size.
void read_texture(const Section& object, const Section& s, SimObject& out) {
  s.allow({"kind", "family", "id", "size_m", "rows", "cols", "square_m", "margin_squares", "image", "dark", "light"});
  if (!s.has("kind")) s.fail("kind", "one of \"apriltag\", \"chessboard\", \"image\"", "nothing");
  const std::string kind = s.string("kind", "", {"apriltag", "chessboard", "image"});
  if (out.material.kind == SimMaterial::Kind::Mirror)
    s.fail("kind",
           fmt::format(
               "expected no texture on a mirror (only Lambertian materials have one), found a {} texture on a mirror",
               kind));
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) s.forbid(k, fmt::format("it applies to {} textures only", which));
  };
  SimTexture& t = out.material.texture;
  if (kind == "image") {
    only({"family", "id", "size_m", "rows", "cols", "square_m", "margin_squares", "dark", "light"},
         "apriltag or chessboard");
    t.kind = SimTexture::Kind::Image;
    if (!object.has("albedo")) out.material.albedo = {1, 1, 1};  // the image's own colours unless scaled
    t.image_path = s.file("image", "an image file (PNG or JPEG)");
    // The header's size is checked before anything decodes the image (sim_textures.cpp again).
    ImageHeader header;
    try {
      header = read_image_header(t.image_path);
    } catch (const AssetError& e) {
      s.fail("image", fmt::format("expected an image file (PNG or JPEG), found one that is not: {}", e.what()));
    }
    if (header.width > kMaxTextureSide || header.height > kMaxTextureSide ||
        header.width * header.height > kMaxTexturePixels)
      s.fail("image", fmt::format("expected an image of at most {} pixels a side and {} pixels in all, found \"{}\": "
                                  "{} x {} {}",
                                  kMaxTextureSide, kMaxTexturePixels, t.image_path.string(), header.width,
                                  header.height, header.format));
    if (!cv::haveImageReader(t.image_path.string()))
      s.fail("image",
             fmt::format("expected an image file OpenCV can decode (PNG or JPEG), found \"{}\", which is not one",
                         t.image_path.string()));
    return;
  }
  s.forbid("image", "it applies to image textures only");
  const std::string why_size =
      kind == "apriltag"
          ? "the apriltag texture sets the plane's size (from texture.size_m)"
          : "the chessboard texture sets the plane's size (from texture.rows, cols, square_m, margin_squares)";
  object.forbid("width_m", why_size);
  object.forbid("height_m", why_size);
  object.forbid("albedo", "a two-tone texture's colours are texture.dark and texture.light");
  t.dark = s.vec3("dark", t.dark, kUnitInterval);
  t.light = s.vec3("light", t.light, kUnitInterval);
  if (kind == "apriltag") {
    only({"rows", "cols", "square_m", "margin_squares"}, "chessboard");
    t.kind = SimTexture::Kind::AprilTag;
    std::vector<std::string_view> families = tag_family_names();
    t.family = s.string("family", "tag36h11", families);
    const TagFamilyPtr family = create_tag_family(t.family);
    t.tag_id = static_cast<int>(s.integer("id", 0, 0, static_cast<int64_t>(family->ncodes) - 1));
    const double size_m = s.number("size_m", 0.1, kPositive);
    // size_m is the black border's edge (AprilTag's tag size); the plane carries the whole pattern.
    out.width_m = out.height_m = size_m * family->total_width / family->width_at_border;
  } else {
    only({"family", "id", "size_m"}, "apriltag");
    t.kind = SimTexture::Kind::Chessboard;
    t.rows = static_cast<int>(s.integer("rows", 7, 2, 1000));
    t.cols = static_cast<int>(s.integer("cols", 10, 2, 1000));
    const double square_m = s.number("square_m", 0.02, kPositive);
    t.margin_squares = s.number("margin_squares", 1.0, kNonNegative);
    out.width_m = (t.cols + 2 * t.margin_squares) * square_m;
    out.height_m = (t.rows + 2 * t.margin_squares) * square_m;
  }
}

SimObject read_object(const Section& s, size_t index) {
  s.allow({"name", "shape", "position", "rotation_deg", "width_m", "height_m", "radius_m", "mesh", "mesh_scale",
           "virtual", "casts_shadows", "material", "albedo", "texture"});
  SimObject out;
  out.name = s.string("name", fmt::format("object{}", index));
  if (out.name.empty()) s.fail("name", "a non-empty name", "an empty string");
  const std::string shape = s.string("shape", "plane", {"plane", "sphere", "mesh"});
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) s.forbid(k, fmt::format("it applies to shape = \"{}\" only, this is a {}", which, shape));
  };
  const Vec3 position = s.vec3("position", {0, 0, 0});
  const Vec3 rotation_deg = s.vec3("rotation_deg", {0, 0, 0});
  out.T_world_object = SE3::from_rt(kRadiansPerDegree * rotation_deg, position);
  out.is_virtual = s.boolean("virtual", out.is_virtual);
  out.casts_shadows = s.boolean("casts_shadows", out.casts_shadows);

  const std::string material = s.string("material", "lambertian", {"lambertian", "mirror"});
  out.material.kind = material == "mirror" ? SimMaterial::Kind::Mirror : SimMaterial::Kind::Lambertian;
  out.material.albedo = s.vec3("albedo", out.material.albedo, kUnitInterval);

  if (shape == "plane") {
    only({"radius_m"}, "sphere");
    only({"mesh", "mesh_scale"}, "mesh");
    out.shape = SimObject::Shape::Plane;
    const auto texture = s.table("texture");
    if (texture) read_texture(s, *texture, out);
    if (out.material.texture.kind == SimTexture::Kind::None || out.material.texture.kind == SimTexture::Kind::Image) {
      out.width_m = s.number("width_m", 1.0, kPositive);
      out.height_m = s.number("height_m", 1.0, kPositive);
    }
  } else if (shape == "sphere") {
    only({"width_m", "height_m", "texture"}, "plane");
    only({"mesh", "mesh_scale"}, "mesh");
    out.shape = SimObject::Shape::Sphere;
    out.radius_m = s.number("radius_m", 0.05, kPositive);
  } else {
    only({"width_m", "height_m", "texture"}, "plane");
    only({"radius_m"}, "sphere");
    out.shape = SimObject::Shape::Mesh;
    const std::string source = s.string("mesh", "");
    if (is_builtin_mesh_source(source)) {
      if (!make_builtin_mesh(source))
        s.fail("mesh", fmt::format("one of {} or a glTF 2.0 file", kBuiltinMeshNames), in_quotes(source));
      out.mesh_builtin = source;
    } else {
      out.mesh_path = s.file("mesh", fmt::format("a glTF 2.0 file (.gltf or .glb) or one of {}", kBuiltinMeshNames));
      try {
        load_gltf_mesh(out.mesh_path);  // the simulator loads it again; this makes a bad file a scene error
      } catch (const AssetError& e) {
        s.fail("mesh", fmt::format("expected a valid glTF 2.0 file, found one that is not ({}): {}",
                                   out.mesh_path.string(), e.what()));
      }
    }
    out.mesh_scale = s.number("mesh_scale", out.mesh_scale, kPositive);
  }
  return out;
}

// ---- [[light]], [sun], [environment] -----------------------------------------------------------

const Range kAngularDiameter{[](double v) { return v >= 0 && v < 180; }, "an angle in [0, 180) degrees"};

Vec3 unit_direction(const Section& s, std::string_view k, const Vec3& fallback) {
  const Vec3 v = s.vec3(k, fallback);
  const double length = norm(v);
  if (length == 0) s.fail(k, "a non-zero direction", show(v));
  return std::abs(length - 1) <= 1e-15 ? v : normalized(v);  // a unit vector stays bit for bit
}

SimLight read_light(const Section& s, size_t index) {
  s.allow({"name", "kind", "color", "direction", "irradiance", "angular_diameter_deg", "position", "intensity",
           "radius_m"});
  SimLight out;
  out.name = s.string("name", fmt::format("light{}", index));
  if (out.name.empty()) s.fail("name", "a non-empty name", "an empty string");
  const std::string kind = s.string("kind", "directional", {"directional", "point", "sphere"});
  const auto only = [&](const std::vector<std::string_view>& keys, std::string_view which) {
    for (const auto k : keys) s.forbid(k, fmt::format("it applies to kind = {} only, this is a {} light", which, kind));
  };
  out.color = s.vec3("color", out.color, kNonNegative);
  if (kind == "directional") {
    only({"position", "intensity"}, "\"point\" or \"sphere\"");
    only({"radius_m"}, "\"sphere\"");
    out.kind = SimLight::Kind::Directional;
    out.direction_to_light = unit_direction(s, "direction", {0, 0, 1});
    out.irradiance = s.number("irradiance", 5.0, kNonNegative);
    out.angular_diameter_rad = s.degrees("angular_diameter_deg", 0.0, kAngularDiameter);
    return out;
  }
  only({"direction", "irradiance", "angular_diameter_deg"}, "\"directional\"");
  if (kind == "point") only({"radius_m"}, "\"sphere\"");
  out.kind = kind == "point" ? SimLight::Kind::Point : SimLight::Kind::Sphere;
  out.position = s.vec3("position", {0, 0, 1});
  out.intensity = s.number("intensity", 1.0, kNonNegative);
  if (kind == "sphere") out.radius_m = s.number("radius_m", 0.02, kPositive);
  return out;
}

// ENU: east = north x up, up = world +z; azimuth from north towards east.
Vec3 sun_direction(const Vec3& north, double azimuth_rad, double elevation_rad) {
  const Vec3 up{0, 0, 1};
  const Vec3 east = cross(north, up);
  const double c = std::cos(elevation_rad);
  return (std::sin(azimuth_rad) * c) * east + (std::cos(azimuth_rad) * c) * north + std::sin(elevation_rad) * up;
}

SimLight read_sun(const Section& s, const Vec3& north, SimSun& sun) {
  s.allow({"azimuth_deg", "elevation_deg", "irradiance", "color", "angular_diameter_deg"});
  sun.azimuth_rad = s.degrees("azimuth_deg", 180 * kRadiansPerDegree);
  sun.elevation_rad = s.degrees("elevation_deg", 45 * kRadiansPerDegree,
                                {[](double v) { return v >= -90 && v <= 90; }, "an elevation in [-90, 90] degrees"});
  SimLight light;
  light.name = "sun";
  light.kind = SimLight::Kind::Directional;
  light.is_sun = true;
  light.direction_to_light = sun_direction(north, sun.azimuth_rad, sun.elevation_rad);
  light.irradiance = s.number("irradiance", 1000.0, kNonNegative);
  light.color = s.vec3("color", light.color, kNonNegative);
  light.angular_diameter_rad = s.degrees("angular_diameter_deg", 0.53 * kRadiansPerDegree, kAngularDiameter);
  return light;
}

SimEnvironment read_environment(const Section& s) {
  s.allow({"hdr", "radiance", "rotation_deg"});
  SimEnvironment out;
  if (s.has("hdr")) {
    out.hdr_path = s.file("hdr", "a Radiance .hdr image");
    std::ifstream in(out.hdr_path, std::ios::binary);
    char magic[2] = {0, 0};
    in.read(magic, 2);
    if (magic[0] != '#' || magic[1] != '?')
      s.fail("hdr", fmt::format("expected a Radiance .hdr image (starting \"#?\"), found \"{}\", which is not one",
                                out.hdr_path.string()));
    out.radiance = {1, 1, 1};  // with an image, radiance is its multiplier
  }
  out.radiance = s.vec3("radiance", out.radiance, kNonNegative);
  out.rotation_rad = s.degrees("rotation_deg", out.rotation_rad);
  return out;
}

// Names must be unique: ground truth and messages refer to objects and lights by name.
template <typename Item>
void check_unique_names(const std::vector<Section>& sections, const std::vector<Item>& items, std::string_view what) {
  std::set<std::string> seen;
  for (size_t i = 0; i < items.size(); ++i)
    if (!seen.insert(items[i].name).second)
      sections[i].fail("name", fmt::format("a name not used by another {}", what),
                       fmt::format("{} a second time", in_quotes(items[i].name)));
}

SimScene read_scene(const Reader& reader, const toml::table& root, const fs::path& base_dir) {
  const Section top(reader, root, "", base_dir);
  top.allow({"description", "world", "camera", "render", "trajectory", "object", "light", "sun", "environment"});
  SimScene scene;
  scene.source_file = reader.source();
  scene.description = top.string("description", "");
  if (const auto world = top.table("world")) scene.world_north = read_world(*world);
  if (const auto camera = top.table("camera")) scene.camera = read_camera(*camera);
  if (const auto render = top.table("render")) scene.render = read_render(*render);
  scene.trajectory = read_trajectory(top.table("trajectory"));

  const std::vector<Section> objects = top.tables("object", kMaxObjects);
  for (size_t i = 0; i < objects.size(); ++i) scene.objects.push_back(read_object(objects[i], i));
  check_unique_names(objects, scene.objects, "object");

  const std::vector<Section> lights = top.tables("light", kMaxLights);
  for (size_t i = 0; i < lights.size(); ++i) scene.lights.push_back(read_light(lights[i], i));
  check_unique_names(lights, scene.lights, "light");
  if (const auto sun = top.table("sun")) {
    scene.sun.emplace();
    scene.lights.push_back(read_sun(*sun, scene.world_north, *scene.sun));
    for (size_t i = 0; i < lights.size(); ++i)
      if (scene.lights[i].name == "sun")
        lights[i].fail("name", "a name other than \"sun\" (the [sun] table adds a light named \"sun\")",
                       in_quotes("sun"));
  }
  if (const auto environment = top.table("environment")) scene.environment = read_environment(*environment);
  return scene;
}

}  // namespace

SimScene parse_sim_scene(const std::string& text, const std::string& source_name,
                         const std::filesystem::path& base_dir) {
  const Reader reader(source_name);
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    reader.syntax_error(e);
  }
  return read_scene(reader, root, base_dir);
}

SimScene load_sim_scene(const std::filesystem::path& path) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw SceneError(fmt::format("{}: cannot read scene file: {}", path.string(), why));
  SimScene scene = parse_sim_scene(*text, path.string(), path.parent_path());
  scene.source_file = path;
  return scene;
}

}  // namespace arpipe::sim
