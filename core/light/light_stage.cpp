// The light stage (see light_stage.h).
#include "core/light/light_stage.h"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "core/environment/environment_light.h"
#include "core/scene/gltf_animation.h"
#include "core/sh/sh_window.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {
namespace {

int64_t realtime_minus_monotonic_ns() {
  timespec real{}, mono{};
  clock_gettime(CLOCK_REALTIME, &real);
  clock_gettime(CLOCK_MONOTONIC, &mono);
  return (int64_t(real.tv_sec) - int64_t(mono.tv_sec)) * 1'000'000'000 + (int64_t(real.tv_nsec) - int64_t(mono.tv_nsec));
}

// The environment's light as the loader read it (light.source = "environment"), and the scene's
// lights for the panorama source (light.panorama.lights_file), strongest first.
struct EnvironmentAssets final : StageAssets {
  std::optional<LightEstimate> environment;
  std::vector<DirectionalLight> scene_lights;
  std::shared_ptr<const GltfAnimation> lights_animation;  // when it moves a light
};

// light.panorama.lights_file's lights in the render's units: a directional light's irradiance is its
// lux times the scale; a point or spot light is a lamp at its place whose irradiance at the world
// origin is its candela over the squared distance (the spot's cone is not modelled); strongest first.
// A lamp at the world origin has no direction from there: left out (warned about when `warn`).
std::vector<DirectionalLight> direct_lights(const std::vector<GltfLight>& file_lights, const SceneLightUnits& units,
                                           bool warn) {
  std::vector<DirectionalLight> out;
  for (const GltfLight& light : file_lights) {
    DirectionalLight d;
    // Punctual lights have no size: the penumbra keeps the config's source size.
    d.angular_diameter_rad = units.angular_diameter_rad;
    if (light.type == "directional") {
      d.direction_world = -1.0 * light.direction;
      d.irradiance = (units.lights_scale * light.intensity) * light.color;
    } else {
      const double distance = norm(light.position);
      if (!(distance > 1e-6)) {
        if (warn)
          log::warn("{}: light \"{}\" (node {}) sits at the world origin: left out", units.file.string(), light.name,
                    light.node);
        continue;
      }
      d.local = true;
      d.position_world = light.position;
      d.direction_world = (1 / distance) * light.position;
      d.irradiance = (units.lights_scale * light.intensity / (distance * distance)) * light.color;
    }
    out.push_back(d);
  }
  std::stable_sort(out.begin(), out.end(), [](const DirectionalLight& a, const DirectionalLight& b) {
    return std::max({a.irradiance[0], a.irradiance[1], a.irradiance[2]}) > std::max({b.irradiance[0], b.irradiance[1], b.irradiance[2]});
  });
  return out;
}

SceneLightUnits scene_light_units(const Config& config) {
  return {config.light.panorama.lights_scale, config.render.shadows.light_angular_diameter_deg * std::numbers::pi / 180,
          config.light.panorama.lights_file};
}

// The file's lights at the animation's start, and the animation when it moves one of them.
void load_scene_lights(const Config& config, EnvironmentAssets& assets) {
  const PanoramaLightConfig& c = config.light.panorama;
  std::vector<GltfLight> file_lights;
  try {
    auto animation = std::make_shared<const GltfAnimation>(GltfAnimation::load(c.lights_file, c.lights_animation));
    file_lights = animation->lights_at(0);
    if (std::any_of(file_lights.begin(), file_lights.end(), [&](const GltfLight& l) { return animation->moves(l.node); }))
      assets.lights_animation = std::move(animation);
  } catch (const std::exception& e) {
    throw ConfigError(fmt::format("{}: light.panorama.lights_file: {}", config.file.string(), e.what()));
  }
  assets.scene_lights = direct_lights(file_lights, scene_light_units(config), true);
  if (assets.scene_lights.empty())
    throw ConfigError(fmt::format("{}: light.panorama.lights_file: {} has no KHR_lights_punctual light on its scene's nodes",
                                  config.file.string(), c.lights_file.string()));
}

}  // namespace

void LightStage::pose_scene_lights(FrameContext& ctx) noexcept {
  // The frame's time on the video's timeline (a still, or a frame without one: the start).
  const int64_t t_ns = ctx.camera.meta.source_frame_time_ns.value_or(0);
  if (panorama_.posed_at_ns == t_ns) return;
  try {
    std::vector<DirectionalLight> lights = direct_lights(panorama_.animation->lights_at(1e-9 * double(t_ns)), panorama_.units, false);
    if (lights.empty()) throw std::runtime_error("every light sits at the world origin");
    panorama_.direct = std::move(lights);
    panorama_.posed_at_ns = t_ns;
  } catch (const std::exception& e) {  // the last posed lights stay
    ctx.light.note = fmt::format("the scene's lights at {:.3f} s: {}", 1e-9 * double(t_ns), e.what());
  }
}

StageAssetLoader LightStage::asset_loader() const {
  return [](const Config& config) -> std::shared_ptr<const StageAssets> {
    auto assets = std::make_shared<EnvironmentAssets>();
    if (config.light.source == LightSource::Environment) assets->environment = load_environment_lighting(config).estimate;
    if (config.light.source == LightSource::Panorama && !config.light.panorama.lights_file.empty())
      load_scene_lights(config, *assets);
    return assets;
  };
}

void LightStage::configure(const Config& config) { configure_loaded(config, asset_loader()(config)); }

void LightStage::configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) {
  const auto* loaded = dynamic_cast<const EnvironmentAssets*>(assets.get());
  if (!loaded) throw std::logic_error("LightStage::configure_loaded: no assets from the light stage's loader");
  const LightConfig& light = config.light;
  const CameraResponse& response = light.response;  // parsed when the config was loaded
  std::unique_ptr<ProbeLightEstimator> probe;
  std::unique_ptr<SunLight> sun;
  LightEstimate environment;
  if (light.source == LightSource::Probe) {
    ProbeLightConfig c;
    c.sphere.kind = light.probe.kind;
    c.sphere.center_world = light.probe.center_m;
    c.sphere.radius_m = light.probe.radius_m;
    c.sphere.reflectance = light.probe.reflectance;
    c.method = light.probe.method;
    c.max_lights = light.probe.max_lights;
    c.smoothing_s = light.smoothing_s;
    c.light_distance_m = light.probe.light_distance_m;
    c.response = response;
    probe = std::make_unique<ProbeLightEstimator>();
    try {
      probe->configure(c);
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: [light.probe]: {}", config.file.string(), e.what()));
    }
  } else if (light.source == LightSource::Sun) {
    sun = std::make_unique<SunLight>();
    sun->configure(light.sun, light.ground_albedo, response, light.smoothing_s, config.file);
  } else if (light.source == LightSource::Environment) {
    if (!loaded->environment) throw std::logic_error("LightStage::configure_loaded: the environment was not loaded");
    environment = *loaded->environment;
    log::info("light: environment {} ({}), ambient L00 = ({:.4g}, {:.4g}, {:.4g})", light.environment.file.string(),
              environment_layout_name(light.environment.layout), environment.ambient_sh[0][0], environment.ambient_sh[0][1],
              environment.ambient_sh[0][2]);
  }
  if (light.source == LightSource::Panorama) {
    // The panorama's own light arrives with each frame (FrameMetadata::environment_sh); the direct
    // lights are the scene's (lights_file) or, when kept, the fixed one (render.light_*), in the
    // same display-referred units.
    panorama_ = PanoramaLighting{};
    panorama_.window = light.panorama.window;
    panorama_.direct = loaded->scene_lights;
    panorama_.animation = loaded->lights_animation;
    panorama_.units = scene_light_units(config);
    if (!light.panorama.lights_file.empty())
      log::info("light: {} direct light(s) from {}, the strongest casting shadows", panorama_.direct.size(),
                light.panorama.lights_file.string());
    else if (light.panorama.direct_light_from_render && norm(config.render.light_color) > 0) {
      DirectionalLight direct;
      direct.direction_world = config.render.light_direction;
      direct.irradiance = std::numbers::pi * config.render.light_color;
      direct.angular_diameter_rad = config.render.shadows.light_angular_diameter_deg * std::numbers::pi / 180;
      direct.local = config.render.light_distance_m > 0;
      direct.position_world = config.render.light_distance_m * config.render.light_direction;
      panorama_.direct = {direct};
    }
  }
  source_ = light.source;
  probe_ = std::move(probe);
  sun_ = std::move(sun);
  environment_ = std::move(environment);
  probe_centre_ = light.probe.center_m;
  ground_albedo_ = light.ground_albedo;
  response_ = response;
  probe_light_distance_m_ = light.probe.light_distance_m;
  hold_ = LightHold({light.probe.hold_direction_deg * std::numbers::pi / 180, light.probe.hold_change}, light.probe.center_m);
  last_note_.clear();
}

void LightStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  if (source_ == LightSource::Fixed) {
    ctx.record_timing(std::string(name()), milliseconds_since(start), "fixed light (render.light_*)");
    return;
  }
  if (source_ == LightSource::Environment) {
    ctx.light = environment_;
    ctx.record_timing(std::string(name()), milliseconds_since(start), "environment file (static)");
    return;
  }
  if (source_ == LightSource::Panorama) {
    const std::optional<ShRgb9>& sh = ctx.camera.meta.environment_sh;
    if (!sh) {
      ctx.light = LightEstimate{};
      ctx.light.note = "the source gave no panorama light with this frame";
      ctx.record_timing(std::string(name()), milliseconds_since(start), "no panorama light");
      return;
    }
    ctx.light = LightEstimate{};
    ctx.light.state = LightState::Estimated;
    ctx.light.source = "panorama";
    ctx.light.ambient_sh = *sh;
    for (size_t i = 0; i < 9; ++i)
      ctx.light.ambient_sh[i] = sh_window_factor(panorama_.window, sh_band(int(i)), 3) * ctx.light.ambient_sh[i];
    if (panorama_.animation) pose_scene_lights(ctx);
    ctx.light.lights = panorama_.direct;
    ctx.light.scene_linear = true;
    ctx.light.confidence = 1;
    ctx.record_timing(std::string(name()), milliseconds_since(start), "the panorama's image");
    return;
  }
  const bool pose_valid = ctx.pose.state == TrackState::Tracking || ctx.pose.state == TrackState::Predicted;
  if (!ctx.camera_model) {
    ctx.record_timing(std::string(name()), milliseconds_since(start), "no camera model");
    return;
  }
  if (source_ == LightSource::Probe) {
    ctx.light = probe_->update(ctx.camera, *ctx.camera_model, ctx.pose.T_cam_world, pose_valid);
    const ProbeDiagnostics& diag = probe_->diagnostics();
    if (diag.measured && !ctx.light.lights.empty() && !diag.light_clipped.empty() && diag.light_clipped.front()) {
      try {
        if (std::optional<Vec3> ground = ground_.measure(ctx.camera, *ctx.camera_model, ctx.pose.T_cam_world, response_))
          if (light_from_ground(ctx.light.lights.front(), ctx.light.ambient_sh, *ground, ground_albedo_))
            ctx.light.note = "light 0 clipped in the probe: its strength is taken from the ground";
      } catch (const std::exception&) {
        // The lower bound stands.
      }
    }
    // A probe sees directions only; a lamp's measured distance places it.
    if (probe_light_distance_m_ > 0 && !ctx.light.lights.empty()) {
      DirectionalLight& key = ctx.light.lights.front();
      key.local = true;
      key.position_world = probe_centre_ + probe_light_distance_m_ * key.direction_world;
      key.direction_world = normalized(key.position_world);
    }
    ctx.light = hold_.apply(ctx.light);
  } else {
    ctx.light = sun_->update(ctx.camera, *ctx.camera_model, ctx.pose.T_cam_world, pose_valid, realtime_minus_monotonic_ns());
  }
  if (!ctx.light.note.empty() && ctx.light.note != last_note_) log::info("light: {}", ctx.light.note);
  last_note_ = ctx.light.note;
  const bool measured = ctx.light.state == LightState::Estimated || ctx.light.state == LightState::NoDirect;
  ctx.record_timing(std::string(name()), milliseconds_since(start),
                    measured ? "" : fmt::format("light {}", light_state_name(ctx.light.state)));
}

}  // namespace arpipe
