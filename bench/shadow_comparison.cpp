// The virtual shadow against the ray-traced truth (see shadow_comparison.h).
#include "bench/shadow_comparison.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "capture/sim/sim_scene_loader.h"
#include "core/image/srgb.h"
#include "core/pipeline/frame_context.h"
#include "render/gl_stages.h"

namespace arpipe::bench {
namespace {

// The camera's pose looking from eye at target, world z up (x right, y down, z forward).
SE3 look_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = normalized(target - eye);
  const Vec3 down = normalized(dot(Vec3{0, 0, 1}, forward) * forward - Vec3{0, 0, 1});
  const Vec3 right = cross(down, forward);
  const Mat3 R_world_cam{{{right[0], down[0], forward[0]}, {right[1], down[1], forward[1]}, {right[2], down[2], forward[2]}}};
  return SE3(R_world_cam, eye).inverse();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

ShadowScene probe_indoor_shadow_scene() {
  // Key: sphere light r 0.03 m at [-0.45, 0.05, 0.45], 2.5 W/sr, colour [1, 0.95, 0.85]; fill:
  // point light at [0.5, -0.4, 0.6], 0.4 W/sr, [0.85, 0.9, 1.0]; sky 0.04 W/(m^2 sr).
  const Vec3 ball{-0.13, -0.09, 0.0295};
  const Vec3 key{-0.45, 0.05, 0.45};
  const Vec3 to_key = key - ball;
  const double d = norm(to_key);
  const Vec3 to_fill = Vec3{0.5, -0.4, 0.6} - Vec3{ball[0], ball[1], 0};
  const double fill = 0.4 / dot(to_fill, to_fill) * normalized(to_fill)[2];
  return {"probe-indoor.toml", ball, 0.03, normalized(to_key), key, (2.5 / (d * d)) * Vec3{1.0, 0.95, 0.85},
          fill * Vec3{0.85, 0.9, 1.0} + (std::numbers::pi * 0.04) * Vec3{1, 1, 1}, 2 * std::asin(0.03 / d),
          look_at({0.04, -0.42, 0.40}, {0.0, 0.04, 0.02}), {-0.22, 0.05, -0.22, 0.0}};
}

ShadowScene sun_outdoor_shadow_scene() {
  // Sun at azimuth 135, elevation 40 (0.53 degree disc), 1000 W/m^2 x [1, 0.96, 0.90]; sky
  // [18, 24, 38] W/(m^2 sr).
  const Vec3 sun{0.5417, -0.5417, 0.6428};
  return {"sun-outdoor.toml", {0.15, -0.10, 0.0395}, 0.04, normalized(sun), {0, 0, 0}, 1000.0 * Vec3{1.0, 0.96, 0.90},
          std::numbers::pi * Vec3{18, 24, 38}, 0.53 * std::numbers::pi / 180,
          look_at({0.08, -0.50, 0.45}, {0.02, 0.05, 0.0}), {0.0, 0.25, -0.25, 0.05}};
}

Config shadow_config(const ShadowScene& scene, const std::string& method_kernel_sky, int map_size) {
  // "pcss+sky": with render.shadows.sky_occlusion.
  const bool sky = method_kernel_sky.size() > 4 && method_kernel_sky.ends_with("+sky");
  const std::string method_and_kernel = sky ? method_kernel_sky.substr(0, method_kernel_sky.size() - 4) : method_kernel_sky;
  // "pcf:8": the method, and the PCF kernel after a colon.
  const size_t colon = method_and_kernel.find(':');
  const std::string method_name = method_and_kernel.substr(0, colon);
  const std::optional<ShadowMethod> method = choice_value(kShadowMethodNames, method_name);
  if (!method) throw std::invalid_argument(fmt::format("shadow method \"{}\": expected one of {}", method_name,
                                                       choice_list(ChoiceNames<ShadowMethod>(kShadowMethodNames))));
  Config config;
  if (colon != std::string::npos) config.render.shadows.pcf_kernel = std::stoi(method_and_kernel.substr(colon + 1));
  config.render.objects = {SceneObject{}};
  config.render.objects[0].mesh = "builtin:sphere";  // r 0.03 m, resting on z = 0
  config.render.objects[0].position_m = {scene.ball_centre[0], scene.ball_centre[1], scene.ball_centre[2] - scene.ball_radius};
  config.render.objects[0].scale = scene.ball_radius / 0.03;
  config.render.objects[0].color = {0.5, 0.5, 0.5};
  config.render.light_direction = scene.towards_light;
  if (norm(scene.light_position) > 0) {
    config.render.light_direction = normalized(scene.light_position);
    config.render.light_distance_m = norm(scene.light_position);
  }
  config.render.light_color = (1 / std::numbers::pi) * scene.direct;
  config.render.ambient = (1 / std::numbers::pi) * scene.ambient;
  config.render.shadows.method = *method;
  config.render.shadows.sky_occlusion = sky;
  config.render.shadows.map_size = map_size;
  config.render.shadows.receiver_height_m = -0.0005;
  config.render.shadows.light_angular_diameter_deg = scene.light_diameter_rad * 180 / std::numbers::pi;
  config.render.blur.method = BlurMethod::Off;
  return config;
}

const ShadowTruth& shadow_truth(const std::filesystem::path& scenes_dir, const ShadowScene& setup) {
  static std::map<std::string, ShadowTruth> cache;
  auto found = cache.find(setup.file);
  if (found != cache.end()) return found->second;
  const sim::SimScene scene = sim::load_sim_scene(scenes_dir / setup.file);
  const CameraModel& camera = scene.camera.model;
  int x0 = camera.width(), y0 = camera.height(), x1 = 0, y1 = 0;
  for (double x : {setup.ground_xy[0], setup.ground_xy[1]})
    for (double y : {setup.ground_xy[2], setup.ground_xy[3]})
      if (auto q = camera.project(setup.camera * Vec3{x, y, 0})) {
        x0 = std::min(x0, int(std::floor((*q)[0])));
        x1 = std::max(x1, int(std::ceil((*q)[0])));
        y0 = std::min(y0, int(std::floor((*q)[1])));
        y1 = std::max(y1, int(std::ceil((*q)[1])));
      }
  ShadowTruth t;
  t.region = {x0, y0, x1, y1};
  t.image = sim::render_shadow_factor(scene, camera, setup.camera, 64, t.region);
  return cache.emplace(setup.file, std::move(t)).first->second;
}

ShadowComparison compare_shadow(const std::filesystem::path& scenes_dir, const ShadowScene& setup,
                                const std::string& method, int map_size, int frames) {
  const sim::SimScene scene = sim::load_sim_scene(scenes_dir / setup.file);
  auto camera = std::make_shared<const CameraModel>(scene.camera.model);
  std::vector<std::unique_ptr<Stage>> stages = make_gl_stages();
  Config config = shadow_config(setup, method, map_size);
  const Config turned = [&] {
    // 0.1 degree about z: past the map's 0.05 degree step, a shadow 5 cm long moves 0.1 mm.
    Config c = config;
    const double a = 0.1 * std::numbers::pi / 180;
    const Vec3 d = c.render.light_direction;
    c.render.light_direction = {std::cos(a) * d[0] - std::sin(a) * d[1], std::sin(a) * d[0] + std::cos(a) * d[1], d[2]};
    return c;
  }();
  Frame white = Frame::allocate(PixelFormat::RGB24, camera->width(), camera->height());
  std::fill(white.data.begin(), white.data.end(), uint8_t{255});
  // One frame of the stages under a config, from the scene's camera pose.
  const auto draw = [&](const Config& with) {
    for (auto& stage : stages) stage->configure(with);
    FrameContext frame;
    frame.camera = white;
    frame.camera_model = camera;
    frame.pose.state = TrackState::Tracking;
    frame.pose.T_cam_world = setup.camera;
    for (auto& stage : stages) stage->process(frame);
    return frame;
  };
  std::vector<double> shadow_ms, render_ms;
  FrameContext ctx;
  for (int i = 0; i < std::max(1, frames); ++i) {
    ctx = draw(i % 2 == 0 ? config : turned);
    for (const StageTiming& t : ctx.timings) {
      if (t.stage == "shadow" && t.skipped.empty()) shadow_ms.push_back(t.ms);
      if (t.stage == "render") render_ms.push_back(t.ms);
    }
  }
  // The last frame must be the unturned light, which the truth has.
  if (frames % 2 == 0) ctx = draw(config);
  const ShadowTruth& t = shadow_truth(scenes_dir, setup);
  ShadowComparison c;
  c.shadow_ms = median(shadow_ms);
  c.render_ms = median(render_ms);
  if (!ctx.virtual_layer_drawn || ctx.output.data.empty()) return c;
  double sum = 0;
  for (int y = t.region.y0; y < t.region.y1; ++y)
    for (int x = t.region.x0; x < t.region.x1; ++x) {
      if (!t.image.valid_at(x, y)) continue;
      // The ball's outline: the truth samples pixel centres, the layer covers pixel areas.
      bool near_ball = false;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx)
          near_ball |= x + dx >= t.region.x0 && x + dx < t.region.x1 && y + dy >= t.region.y0 && y + dy < t.region.y1 &&
                       !t.image.valid_at(x + dx, y + dy);
      if (near_ball) continue;
      const double ours = srgb_decode(ctx.output.data[size_t(y) * ctx.output.bytes_per_line + size_t(x) * 3 + 1] / 255.0);
      const double truth_ratio = t.image.at(x, y);
      if (ours > 0.98 && truth_ratio > 0.98) continue;
      sum += std::abs(ours - truth_ratio);
      ++c.pixels;
      c.truth_min = std::min(c.truth_min, truth_ratio);
    }
  c.mae = c.pixels ? sum / c.pixels : 1.0;
  return c;
}

}  // namespace arpipe::bench
