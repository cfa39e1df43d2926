// Reading a config: the overrides are merged into the parsed tree, then the schema rows
// (config.h's visit functions) are walked with a TomlSection, so the file and the command line are
// checked alike; the checks between keys follow the rows of their table.
#include <apriltag/apriltag.h>
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <set>

#include "core/config/config.h"
#include "core/config/config_overrides.h"
#include "core/config/listen_address.h"
#include "core/config/text_file.h"
#include "core/config/toml_section.h"
#include "core/image/camera_response.h"
#include "core/scene/builtin_meshes.h"
#include "core/track/tag_family.h"

namespace arpipe {

namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

std::string one_of_ints_phrase(const OneOfInts& rule) {
  if (!rule.phrase.empty()) return rule.phrase;
  std::string out = "one of ";
  for (size_t i = 0; i < rule.values.size(); ++i) out += fmt::format("{}{}", i == 0 ? "" : ", ", rule.values[i]);
  return out;
}

std::string one_of_phrase(const std::vector<std::string_view>& names) {
  std::string out = "one of ";
  for (size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : ", ") + toml_quoted(names[i]);
  return out;
}

void check_cross_keys(const TomlSection& t, SourceConfig& s) {
  if (s.type == SourceType::Panorama && s.panorama.file.empty())
    t.fail_with("type", "expected source.panorama.file to be set when the type is \"panorama\"");
  if (s.reconnect_max_ms < s.reconnect_min_ms)
    t.fail(t.has("reconnect_max_ms") ? "reconnect_max_ms" : "reconnect_min_ms",
           fmt::format("at least reconnect_min_ms ({})", s.reconnect_min_ms), fmt::format("{}", s.reconnect_max_ms));
}

void check_cross_keys(const TomlSection& t, RawColourConfig& s) {
  if (s.white_level > 0)
    for (double black : s.black_level)
      if (!(black < s.white_level))
        t.fail("black_level", fmt::format("codes below white_level ({})", s.white_level), fmt::format("{}", black));
  // The defaults document writes unit gains with every mode; other gains would be silently unused.
  if (s.gains != Vec3{1, 1, 1} && s.white_balance != WhiteBalanceMode::Fixed)
    t.fail_with("gains", "expected white_balance = \"fixed\" with gains other than [1, 1, 1] (they are used only then)");
}

void check_cross_keys(const TomlSection& t, PanoramaViewpoint& s) {
  if (s.file.empty()) t.fail_with("file", "expected the viewpoint's panorama file");
}

void check_cross_keys(const TomlSection& t, PanoramaConfig& s) {
  if (s.viewpoints.size() + 1 > PanoramaConfig::kMaxViewpoints)
    t.fail_with("viewpoints", fmt::format("{} viewpoints, more than the limit of {}", s.viewpoints.size() + 1,
                                          PanoramaConfig::kMaxViewpoints));
  if (!s.viewpoints.empty() && s.view.dwell_s <= 0)
    t.fail_with("viewpoints", "expected source.panorama.view.dwell_s > 0 with more than one viewpoint (the time at each)");
  if (s.pole_merge_to_rad < s.pole_merge_from_rad)
    t.fail("pole_merge_to_deg", fmt::format("at least pole_merge_from_deg ({:g})", s.pole_merge_from_rad * 180 / std::numbers::pi),
           fmt::format("{:g}", s.pole_merge_to_rad * 180 / std::numbers::pi));
}

void check_cross_keys(const TomlSection& t, PanoramaViewConfig& s) {
  if (!s.track.empty() && (s.yaw_rad_per_s != 0 || s.pitch_rad != 0))
    t.fail_with(s.yaw_rad_per_s != 0 ? "yaw_deg_per_s" : "pitch_deg",
                "expected 0 with a track: the track gives the orientation over time (yaw_deg still turns it)");
}

void check_cross_keys(const TomlSection& t, TrackConfig& s) {
  if (!t.has("bundle")) return;  // the default bundle (tag 0) exists in every family
  const int64_t code_count = create_tag_family(s.family)->ncodes;
  const std::vector<TomlSection> tags = t.sections("bundle");
  std::set<int> ids;
  for (size_t i = 0; i < tags.size(); ++i) {
    const int id = s.bundle[i].id;
    if (id < 0 || id >= code_count)
      tags[i].fail("id", fmt::format("an integer in [0, {}]", code_count - 1), fmt::format("{}", id));
    if (!ids.insert(id).second) tags[i].fail("id", "an id not used by another tag of the bundle", fmt::format("{} a second time", id));
  }
  if (s.enabled && s.bundle.empty()) t.fail_with("bundle", "expected at least one tag while tracking is enabled");
}

void check_cross_keys(const TomlSection& t, ShadowConfig& s) {
  if (s.vsm_blur % 2 == 0)
    t.fail("vsm_blur", "an odd integer in [1, 31] (taps across a centred kernel)", fmt::format("{}", s.vsm_blur));
}

void check_cross_keys(const TomlSection& t, LightConfig& s) {
  if (s.source == LightSource::Environment && s.environment.file.empty())
    t.fail_with("source", "expected light.environment.file to be set when the source is \"environment\"");
}

void check_cross_keys(const TomlSection& t, RenderConfig& s) {
  const double length = norm(s.light_direction);
  if (length == 0) t.fail_with("light_direction", "expected a non-zero direction");
  // A vector already of unit length is kept bit for bit, so printing and reading a config is exact.
  if (std::abs(length - 1.0) > 1e-12) s.light_direction = normalized(s.light_direction);
}

void check_cross_keys(const TomlSection& t, HttpSinkConfig& s) {
  std::string why;
  if (!parse_listen_address(s.listen, why)) t.fail("listen", why, toml_quoted(s.listen));
}

void check_cross_keys(const TomlSection& t, ObjectPhysics& s) {
  for (size_t i = 1; i < s.track.size(); ++i)
    if (!(s.track[i].time_s > s.track[i - 1].time_s))
      t.fail_with("track", fmt::format("expected the keys' time_s to increase; key {} has {} after {}", i,
                                       toml_float(s.track[i].time_s), toml_float(s.track[i - 1].time_s)));
  if (!s.track.empty() && s.kind != ObjectMotion::Kinematic)
    t.fail_with("track", fmt::format("a pose track moves only a kinematic body, not a {} one", object_motion_name(s.kind)));
}

void check_cross_keys(const TomlSection& t, SceneProxy& s) {
  const bool builtin = is_builtin_mesh_source(s.mesh);
  if (builtin && !s.node.empty()) t.fail_with("node", fmt::format("a node is a glTF file's; mesh is {}", toml_quoted(s.mesh)));
  if (builtin && s.skip_animated_nodes)
    t.fail_with("skip_animated_nodes", fmt::format("animated nodes are a glTF file's; mesh is {}", toml_quoted(s.mesh)));
  if (!s.node.empty() && s.skip_animated_nodes)
    t.fail_with("skip_animated_nodes", "a proxy takes one node (node) or the file without its moving nodes, not both");
}

void check_cross_keys(const TomlSection& t, Config& c) {
  if (c.light.source == LightSource::Panorama && c.source.type != SourceType::Panorama)
    t.fail_with("light", "light.source = \"panorama\" needs source.type = \"panorama\" (the light is the panorama's image)");
  // A proxy's viewpoint must be one the source has.
  const int viewpoints = c.source.type == SourceType::Panorama ? int(c.source.panorama.viewpoint_count()) : 0;
  for (size_t i = 0; i < c.render.proxies.size(); ++i) {
    const int k = c.render.proxies[i].viewpoint;
    if (k < viewpoints) continue;
    const std::string expected =
        viewpoints == 0 ? "-1 (viewpoints belong to a panorama source)" : fmt::format("-1 or a viewpoint in [0, {}]", viewpoints - 1);
    if (const std::optional<TomlSection> render = t.section("render"))
      if (const std::vector<TomlSection> proxies = render->sections("proxies"); i < proxies.size())
        proxies[i].fail("viewpoint", expected, fmt::format("{}", k));
    t.fail_with("render", fmt::format("render.proxies[{}].viewpoint: expected {}, found {}", i, expected, k));
  }
}

template <class Section>
void check_cross_keys(const TomlSection&, Section&) {}

// The visitor that reads rows from one TomlSection; each row keeps its member when the key is absent.
class RowReader {
 public:
  explicit RowReader(const TomlSection& section) : t_(section) {}

  void key(std::string_view name, bool& member, std::string_view) { member = t_.boolean(name, member); }
  void key(std::string_view name, std::string& member, std::string_view) { member = t_.string(name, member); }
  void key(std::string_view name, std::filesystem::path& member, std::string_view) { member = t_.path(name, member); }
  void key(std::string_view name, double& member, std::string_view) { member = t_.number(name, member); }
  void key(std::string_view name, Vec3& member, std::string_view) { member = t_.vec3(name, member); }

  void key(std::string_view name, int& member, const IntRange& range, std::string_view) {
    member = t_.integer_as<int>(name, member, range);
  }
  void key(std::string_view name, int64_t& member, const IntRange& range, std::string_view) {
    member = t_.integer(name, member, range);
  }
  void key(std::string_view name, int& member, const OneOfInts& rule, std::string_view) {
    const int64_t value = t_.integer(name, member);
    if (std::find(rule.values.begin(), rule.values.end(), value) == rule.values.end())
      t_.fail(name, one_of_ints_phrase(rule), fmt::format("{}", value));
    member = static_cast<int>(value);
  }
  void key(std::string_view name, double& member, const NumberRange& range, std::string_view) {
    member = t_.number(name, member, range);
  }
  void key(std::string_view name, Vec3& member, const NumberRange& range, std::string_view) {
    member = t_.vec3(name, member, range);
  }
  void key(std::string_view name, std::vector<double>& member, const NumberCount& rule, std::string_view) {
    if (!t_.has(name)) return t_.allow(name);
    const std::vector<double> values = t_.number_list(name, {}, rule.range, 64);
    if (std::find(rule.counts.begin(), rule.counts.end(), values.size()) == rule.counts.end())
      t_.fail(name, rule.phrase, fmt::format("{} numbers", values.size()));
    member = values;
  }
  void key(std::string_view name, double& member_rad, const Degrees& rule, std::string_view) {
    if (!t_.has(name)) return t_.allow(name);  // the default stays bit for bit
    member_rad = t_.number(name, 0, rule.range) * kRadiansPerDegree;
  }
  void key(std::string_view name, Vec3& member_rad, const Degrees& rule, std::string_view) {
    if (!t_.has(name)) return t_.allow(name);
    member_rad = kRadiansPerDegree * t_.vec3(name, {0, 0, 0}, rule.range);
  }
  // An array of distinct role names; the roles it names are on, the others off.
  void key(std::string_view name, ProxyRoles& member, const ProxyRoleNames&, std::string_view) {
    const toml::node* node = t_.node(name);
    if (node == nullptr) return;
    const std::string expected = "an array of distinct names, each " + one_of_phrase({std::begin(kProxyRoleNames), std::end(kProxyRoleNames)});
    const toml::array* array = node->as_array();
    if (array == nullptr) t_.fail(name, expected, std::string(toml_type_phrase(*node)));
    ProxyRoles roles{false, false, false, false};
    for (const toml::node& item : *array) {
      if (!item.is_string()) t_.fail(name, expected, std::string(toml_type_phrase(item)) + " in the array");
      const std::string& value = item.as_string()->get();
      const auto found = std::find(std::begin(kProxyRoleNames), std::end(kProxyRoleNames), value);
      if (found == std::end(kProxyRoleNames)) t_.fail(name, expected, toml_quoted(value));
      bool& flag = proxy_role(roles, static_cast<size_t>(found - std::begin(kProxyRoleNames)));
      if (flag) t_.fail(name, expected, toml_quoted(value) + " twice");
      flag = true;
    }
    member = roles;
  }
  void key(std::string_view name, int64_t& member_ns, const MillisecondsAsNs& rule, std::string_view) {
    if (!t_.has(name)) return t_.allow(name);
    const double ms = t_.number(name, 0, rule.range);
    member_ns = std::llround(ms * 1e6);
    if (member_ns <= 0) t_.fail(name, "at least 1 ns", toml_float(ms));
  }
  void key(std::string_view name, std::string& member, const OneOf& rule, std::string_view) {
    string_satisfying(name, member, one_of_phrase(rule.names), [&](const std::string& value) {
      return std::find(rule.names.begin(), rule.names.end(), value) != rule.names.end();
    });
  }
  void key(std::string_view name, std::string& member, const NotEmpty& rule, std::string_view) {
    string_satisfying(name, member, rule.phrase, [](const std::string& value) { return !value.empty(); });
  }
  void key(std::string_view name, std::string& member, const TagFamilyName&, std::string_view) {
    string_satisfying(name, member, one_of_phrase(tag_family_names()),
                      [](const std::string& value) { return is_tag_family(value); });
  }
  // Parsed once here by core/image/camera_response's own rule, the one the simulator uses too.
  void key(std::string_view name, CameraResponse& member, const CameraResponseName&, std::string_view) {
    member = t_.parsed<CameraResponse>(name, member, CameraResponse::from_name,
                                       "\"srgb\", \"linear\" or \"gamma:<g>\" with g > 0");
  }

  // A choice: its name table's names and aliases.
  template <class E, size_t N>
  void key(std::string_view name, E& member, const ChoiceName<E> (&names)[N], std::string_view) {
    member = t_.choice(name, member, names);
  }

  template <class Section>
  void section(std::string_view name, Section& member, std::string_view) {
    if (const auto sub = t_.section(name)) read_section(*sub, member);
  }
  // A table whose presence turns its part on (a sink): `enabled` is true unless the table says not.
  template <class Section>
  void switched_section(std::string_view name, Section& member, std::string_view) {
    if (const auto sub = t_.section(name)) {
      member.enabled = true;
      read_section(*sub, member);
    }
  }
  template <class Element>
  void sections(std::string_view name, std::vector<Element>& member, std::string_view) {
    if (!t_.has(name)) return t_.allow(name);
    member.clear();
    for (const TomlSection& sub : t_.sections(name)) {
      Element element;
      read_section(sub, element);
      member.push_back(element);
    }
  }

  template <class Section>
  static void read_section(const TomlSection& t, Section& member) {
    RowReader reader(t);
    visit(reader, member);
    check_cross_keys(t, member);
  }

 private:
  template <class Ok>
  void string_satisfying(std::string_view name, std::string& member, const std::string& expected, Ok ok) {
    const toml::node* node = t_.node(name);
    if (node == nullptr) return;
    if (!node->is_string()) t_.fail(name, expected, std::string(toml_type_phrase(*node)));
    const std::string& value = node->as_string()->get();
    if (!ok(value)) t_.fail(name, expected, toml_quoted(value));
    member = value;
  }

  const TomlSection& t_;
};

}  // namespace

Config parse_config(const std::string& text, const std::string& source_name, const std::vector<std::string>& overrides) {
  try {
    toml::table root = parse_toml(text, source_name);
    for (const std::string& assignment : overrides) apply_override(root, assignment);
    Config config;
    config.file = source_name;
    const TomlSection file(root, source_name);
    RowReader::read_section(file, config);
    file.reject_stray_keys();
    return config;
  } catch (const TomlInputError& e) {
    throw ConfigError(e.what());
  }
}

Config load_config(const std::filesystem::path& path, const std::vector<std::string>& overrides) {
  std::string why;
  const auto text = read_text_file(path, why);
  if (!text) throw ConfigError(fmt::format("{}: cannot read config: {}", path.string(), why));
  Config config = parse_config(*text, path.string(), overrides);
  config.file = path;
  return config;
}

}  // namespace arpipe
