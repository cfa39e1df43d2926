// The render stage: draws the scene's virtual objects, seen from the tracked pose through the
// calibrated lens (render.lens: warped canvas, per-vertex distortion, or the undistorted pinhole
// core), into the shared virtual layer (linear, premultiplied alpha, depth-tested).
#include "render/render_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "core/sh/sh_basis.h"
#include "core/sh/sh_irradiance.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"
#include "render/gl/gl_error.h"
#include "render/gl/pass_times.h"
#include "render/lens/lens_projection.h"
#include "render/lens/lens_undistortion.h"
#include "render/projected_bounds.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// Covers the multisampled edge pixels and the bend of distorted edges between sampled points.
constexpr double kRectMarginPx = 2.0;
constexpr int kExposureInstants = 8;  // pieces of the exposure whose ends bound the footprint
// The shadow map follows the light in steps of this angle, so that a light estimate's
// frame-to-frame jitter does not redraw it every frame (a shadow 10 cm long moves 0.1 mm).
constexpr double kRadiansPerDegree = std::numbers::pi / 180;
constexpr double kShadowLightStepRad = 0.05 * kRadiansPerDegree;
// The ground catcher's square split per side when its vertices move non-linearly (a lens per
// vertex, a stereo panorama's eye), so that it bends like the ground.
constexpr int kBentReceiverSubdivisions = 16;

// What the render stage's loader reads away from the processing thread: the objects' meshes and
// their PRT transfers, on the CPU.
struct RenderAssets final : StageAssets {
  LoadedMeshes meshes;
};

// The world-frame axis-aligned box around `box` (an object's frame) placed by T_world_object.
Bounds world_box(const Bounds& box, const SE3& T_world_object) {
  Bounds world{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (const Vec3& corner : box_corners(box)) {
    const Vec3 w = T_world_object * corner;
    for (size_t k = 0; k < 3; ++k) {
      world.min[k] = std::min(world.min[k], w[k]);
      world.max[k] = std::max(world.max[k], w[k]);
    }
  }
  return world;
}

}  // namespace

RenderStage::RenderStage(std::shared_ptr<RenderSession> session) : session_(std::move(session)) {}

RenderStage::~RenderStage() {
  session_->try_make_current();
  objects_.clear();
  proxies_.clear();
  real_shadow_pass_.reset();
  warp_pass_.reset();
  shadow_pass_.reset();
  receiver_.reset();
  catcher_bake_.reset();
  drawer_.reset();
}

StageAssetLoader RenderStage::asset_loader() const {
  return [](const Config& config) -> std::shared_ptr<const StageAssets> {
    auto assets = std::make_shared<RenderAssets>();
    assets->meshes = load_object_meshes(config);
    return assets;
  };
}

void RenderStage::configure(const Config& config) { configure_loaded(config, asset_loader()(config)); }

void RenderStage::configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) {
  const auto* loaded = dynamic_cast<const RenderAssets*>(assets.get());
  if (!loaded) throw std::logic_error("RenderStage::configure_loaded: no assets from the render stage's loader");
  session_->ensure_context(config.render.egl_platform);
  session_->make_current();
  if (!drawer_) drawer_ = std::make_unique<MotionBlurDrawer>(session_->context(), session_->layer().color_format());
  drawer_->prepare(config.render.blur.method);
  // A stereo layout's objects and proxies are cut for its eyes now; an "auto" one's on its first
  // eye's frame.
  const bool stereo = config.source.type == SourceType::Panorama && is_stereo(config.source.panorama.layout);
  std::vector<UploadedObject> objects = upload_objects(config, loaded->meshes, stereo);
  std::vector<UploadedObject> proxies = upload_proxies(config, loaded->meshes, stereo);
  auto physics = std::make_unique<ScenePhysics>(config, loaded->meshes);
  if (physics->empty()) physics.reset();
  std::unique_ptr<OcclusionMeter> occlusion_meter;
  if (!config.render.proxies.empty() || physics) occlusion_meter = std::make_unique<OcclusionMeter>(config, loaded->meshes);

  Settings settings;
  settings.enabled = config.render.enabled;
  settings.msaa_samples = config.render.msaa_samples;
  const double light_length = norm(config.render.light_direction);
  settings.light_direction = light_length > 0 ? (1.0 / light_length) * config.render.light_direction : Vec3{0, 0, 1};
  settings.light_distance_m = config.render.light_distance_m;
  settings.light_color = config.render.light_color;
  settings.ambient = config.render.ambient;
  settings.lens = config.render.lens;
  settings.lens_canvas_scale = config.render.lens_canvas_scale;
  settings.rolling_shutter = config.render.rolling_shutter;
  settings.max_predicted_uncertainty_deg = config.render.max_predicted_uncertainty_deg;
  settings.reuse_layer = config.render.reuse_layer;
  settings.full_canvas = config.render.full_canvas;
  settings.ods = config.source.panorama.ods_rig();
  settings.occluder_lod_px = config.render.occluder_lod_px;
  settings.default_exposure_ns = config.motion.default_exposure_ns;
  settings.blur = config.render.blur;
  settings.shadows = config.render.shadows;
  settings.shadow_method = config.render.shadows.method;
  drawer_->prepare_shadows(settings.shadow_method);
  if (settings.shadow_method == ShadowMethod::Off) {
    shadow_pass_.reset();
  } else if (!shadow_pass_ || shadow_pass_->config() != settings.shadows) {
    shadow_pass_ = std::make_unique<ShadowMapPass>(session_->context(), settings.shadows);
  }
  // Split so that lens distortion applied per vertex, or a stereo panorama's eye offset
  // (core/geometry/ods_projection.h), bends it like the ground in the image.
  const int receiver_subdivisions = settings.lens == LensMode::Vertex || stereo ? kBentReceiverSubdivisions : 1;
  if (!receiver_ || receiver_->subdivisions() != receiver_subdivisions)
    receiver_ = std::make_unique<ShadowReceiver>(receiver_subdivisions);
  // The real casters' map: a depth map for the catcher's real visibility (shadow_lookup_glsl.h).
  const bool real_casters = std::any_of(proxies.begin(), proxies.end(), [](const UploadedObject& p) { return p.casts_shadows; });
  // The same method and size as the main map, so that where no virtual object casts, the two
  // lookups agree exactly and the catcher's ratio is 1.
  const ShadowConfig& real_shadow_config = settings.shadows;
  if (settings.shadow_method == ShadowMethod::Off || !real_casters) real_shadow_pass_.reset();
  else if (!real_shadow_pass_ || real_shadow_pass_->config() != real_shadow_config)
    real_shadow_pass_ = std::make_unique<ShadowMapPass>(session_->context(), real_shadow_config);

  // The warp's shader is compiled here rather than on the first frame that needs it.
  if (settings.lens == LensMode::Map && !warp_pass_)
    warp_pass_ = std::make_unique<LensWarpPass>(session_->layer().color_format());

  objects_ = std::move(objects);
  proxies_ = std::move(proxies);
  animator_ = std::make_unique<ProxyAnimator>(config, loaded->meshes, proxies_);
  cut_for_stereo_ = stereo;
  assets_ = assets;
  proxy_config_ = config;
  physics_ = std::move(physics);
  occlusion_meter_ = std::move(occlusion_meter);
  reuse_.forget();  // new objects or settings: draw again
  if (settings.lens_canvas_scale != settings_.lens_canvas_scale) warp_maps_.clear();
  settings_ = settings;
  last_error_.clear();
}

void RenderStage::prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept {
  if (!camera_model || !settings_.enabled || objects_.empty()) return;
  try {
    if (settings_.lens == LensMode::Map) warp_map(camera_model);
    if (settings_.lens == LensMode::Undistort) pinhole_core(camera_model);
  } catch (...) {
    // The cache keeps the error; the frames report it.
  }
}

std::shared_ptr<const LensWarpMap> RenderStage::warp_map(const std::shared_ptr<const CameraModel>& camera_model) {
  return warp_maps_.get(camera_model, [scale = settings_.lens_canvas_scale](const CameraModel& model) {
    return LensWarpMap(model, scale);
  });
}

std::shared_ptr<const CameraModel> RenderStage::pinhole_core(const std::shared_ptr<const CameraModel>& camera_model) {
  return pinhole_cores_.get(camera_model, [](const CameraModel& model) {
    check_lens_undistortable(model);
    return CameraModel::pinhole(model.fx(), model.fy(), model.cx(), model.cy(), model.width(), model.height());
  });
}

void RenderStage::prepare_for_stereo() {
  // The first eye's frame of an "auto" layout that turned out stereo: the objects and proxies cut
  // for the eyes' offsets, the ground catcher's square split.
  if (!cut_for_stereo_ && !objects_.empty()) {
    const auto* loaded = dynamic_cast<const RenderAssets*>(assets_.get());
    if (!loaded) throw std::logic_error("RenderStage: no assets to cut the objects from");
    // Only the meshes change: the objects keep their places (and the physics its bodies).
    const std::vector<UploadedObject> cut = upload_objects(proxy_config_, loaded->meshes, true);
    for (size_t i = 0; i < objects_.size() && i < cut.size(); ++i) objects_[i].mesh = cut[i].mesh;
    reuse_.forget();
  }
  if (!cut_for_stereo_ && !proxies_.empty()) {
    const auto* loaded = dynamic_cast<const RenderAssets*>(assets_.get());
    if (!loaded) throw std::logic_error("RenderStage: no assets to cut the proxies from");
    proxies_ = upload_proxies(proxy_config_, loaded->meshes, true);
    animator_ = std::make_unique<ProxyAnimator>(proxy_config_, loaded->meshes, proxies_);
    reuse_.forget();
  }
  cut_for_stereo_ = true;
  if (receiver_ && receiver_->subdivisions() < kBentReceiverSubdivisions)
    receiver_ = std::make_unique<ShadowReceiver>(kBentReceiverSubdivisions);
}

// FrameContext::virtual_layer carries the texture's name without the GL headers.
static_assert(sizeof(GLuint) == sizeof(VirtualLayerTexture::texture));

void RenderStage::process(FrameContext& ctx) noexcept {
  const auto start = std::chrono::steady_clock::now();
  ctx.virtual_layer_drawn = false;
  ctx.virtual_layer = {};
  try {
    // Animated proxies stand where the frame's time puts them, drawn or not (results say where).
    if (settings_.enabled && animator_ && !animator_->empty()) {
      if (ctx.camera.meta.eye != Eye::Mono) prepare_for_stereo();  // the cut proxies are the ones placed
      AnimationReport report;
      if (animator_->place(proxies_, ctx.camera.meta.source_frame_time_ns, report)) reuse_.forget();
      ctx.animation = std::move(report);
    }
    std::string skip;
    if (!settings_.enabled) skip = "render disabled";
    else if (objects_.empty()) skip = "no objects";
    // A predicted pose is drawn too: detection fails exactly on the strongly blurred frames
    // that need the blur most.
    else if (ctx.pose.state != TrackState::Tracking && ctx.pose.state != TrackState::Predicted)
      skip = fmt::format("pose {}", track_state_name(ctx.pose.state));
    else if (ctx.pose.state == TrackState::Predicted &&
             ctx.pose.predicted_uncertainty_deg > settings_.max_predicted_uncertainty_deg)
      skip = fmt::format("predicted pose too uncertain ({:.1f} > {:.1f} deg)", ctx.pose.predicted_uncertainty_deg,
                         settings_.max_predicted_uncertainty_deg);
    if (!skip.empty()) {
      ctx.record_timing(std::string(name()), milliseconds_since(start), std::move(skip));
      return;
    }
    switch (draw(ctx)) {
      case Drawn::Yes:
        ctx.record_timing(std::string(name()), milliseconds_since(start));
        last_error_.clear();
        break;
      case Drawn::Reused:
        ctx.record_timing(std::string(name()), milliseconds_since(start), "reused: pose, light and objects unchanged");
        break;
      case Drawn::OutOfView:
        ctx.record_timing(std::string(name()), milliseconds_since(start), "objects out of view");
        break;
    }
  } catch (const std::exception& e) {
    ctx.virtual_layer_drawn = false;
    if (last_error_ != e.what()) log::error("render: {}", e.what());
    last_error_ = e.what();
    ctx.record_timing(std::string(name()), milliseconds_since(start), fmt::format("error: {}", e.what()));
  } catch (...) {
    ctx.virtual_layer_drawn = false;
    ctx.record_timing(std::string(name()), milliseconds_since(start), "error: unknown exception");
  }
}

namespace {
// The ground catcher's box where it can draw (object frame): with a bake, the bake's reach (its
// square stands unrotated, centred on the catcher's origin); nullopt where it draws nothing.
std::optional<Bounds> catcher_drawn_box(const UploadedObject& catcher, const Lighting::BakedCatcher& baked) {
  if (baked.texture == 0) return catcher.bounds;
  const auto& [x0, y0, x1, y1] = baked.reach;
  if (!(x0 <= x1 && y0 <= y1)) return std::nullopt;
  const Vec3 origin = catcher.T_world_object.translation();
  Bounds box = catcher.bounds;
  box.min[0] = std::max(box.min[0], double(x0) - origin[0]), box.max[0] = std::min(box.max[0], double(x1) - origin[0]);
  box.min[1] = std::max(box.min[1], double(y0) - origin[1]), box.max[1] = std::min(box.max[1], double(y1) - origin[1]);
  if (!(box.min[0] <= box.max[0] && box.min[1] <= box.max[1])) return std::nullopt;
  return box;
}

// Process-wide, so that no two drawings (of this stage or of one built by a reload) share a number.
uint64_t next_layer_generation() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}
}  // namespace

RenderStage::Drawn RenderStage::draw(FrameContext& ctx) {
  if (!ctx.camera_model) throw RenderError("the frame has no camera model");
  const CameraModel& camera = *ctx.camera_model;
  if (camera.width() != ctx.camera.width || camera.height() != ctx.camera.height)
    throw RenderError(fmt::format("the camera frame is {}x{} but the camera model is for {}x{}", ctx.camera.width,
                                  ctx.camera.height, camera.width(), camera.height()));
  if (settings_.lens == LensMode::Vertex) check_lens_model_supported(camera);
  // What the output picture sees: the camera's lens, or its pinhole core when the composite
  // stage undistorts the camera frame.
  const std::shared_ptr<const CameraModel> core =
      settings_.lens == LensMode::Undistort ? pinhole_core(ctx.camera_model) : nullptr;
  const CameraModel& image_camera = core ? *core : camera;

  // The frame's motion. Objects that move themselves blur even when the camera's motion is not
  // known: the camera then counts as still over the exposure.
  ShutterMotion motion = ctx.motion;
  if (physics_ && !motion.valid()) {
    motion.state = MotionState::Extrapolated;
    motion.timing = shutter_timing(ctx.camera.meta, camera.height(), settings_.default_exposure_ns);
    motion.pose_time_ns = motion.timing.mid_ns();
    motion.T_cam_world_start = motion.T_cam_world_mid = motion.T_cam_world_end = ctx.pose.T_cam_world;
    motion.max_image_motion_px = 0;
  }
  if (ctx.camera.meta.eye != Eye::Mono) prepare_for_stereo();
  if (physics_) physics_->set_viewpoint(ctx.camera.meta.viewpoint);  // its proxies' colliders only
  if (physics_ && move_objects(motion)) reuse_.forget();
  if (physics_) {
    PhysicsReport report;
    report.restarts = physics_->restarts();
    if (const RigidWorldStats* stats = physics_->stats()) {
      report.substeps = stats->substeps;
      report.capped_advances = stats->capped_advances;
      report.removed_below_floor = stats->removed_below_floor;
      report.removed_beyond_radius = stats->removed_beyond_radius;
      report.removed_non_finite = stats->removed_non_finite;
    }
    ctx.physics = report;
  }
  if (occlusion_meter_) {
    const auto measure_start = std::chrono::steady_clock::now();
    ctx.objects = occlusion_meter_->measure(camera, ctx.pose.T_cam_world, objects_, proxies_, ctx.camera.meta.viewpoint,
                                            ctx.camera.meta.eye, settings_.ods);
    ctx.record_timing("occlusion", milliseconds_since(measure_start));
  }

  // The rectangle the objects can reach over the exposure (blurred, or skewed by a rolling
  // shutter): their boxes at 9 instants from its start to its end, so that a path whose ends lie
  // outside the picture still counts where it crosses it (the margin covers the bend between).
  struct Instant {
    SE3 T_cam_world;
    int64_t t_ns;
  };
  std::vector<Instant> instants{{ctx.pose.T_cam_world, ctx.camera.meta.exposure_mid_ns()}};
  if (motion.valid()) {
    const int64_t start = motion.timing.exposure_start_ns, span = motion.timing.end_ns() - start;
    for (int k = 0; k <= kExposureInstants; ++k) {
      const int64_t t = start + span * k / kExposureInstants;
      instants.push_back({motion.T_cam_world_at(t), t});
    }
  }
  std::vector<SE3> exposure_poses;
  for (const Instant& instant : instants) exposure_poses.push_back(instant.T_cam_world);
  // A stereo panorama's eye draws each point moved by less than its eye's offset (ipd / 2), in
  // any direction: boxes grown by that hold everything drawn.
  const Eye eye = ctx.camera.meta.eye;
  const double eye_offset_m = eye == Eye::Mono ? 0.0 : 0.5 * settings_.ods.ipd_m;
  const auto drawn_box = [eye_offset_m](const Bounds& box) {
    const Vec3 grow{eye_offset_m, eye_offset_m, eye_offset_m};
    return Bounds{box.min - grow, box.max + grow};
  };
  const auto rect_of = [&](const UploadedObject& object, PixelRect& into) {
    bool in_view = false;
    for (const Instant& instant : instants) {
      const SE3 T_world_object = object.pose_at ? object.pose_at(instant.t_ns) : object.T_world_object;
      if (std::optional<PixelRect> r = projected_box_rect(image_camera, instant.T_cam_world * T_world_object,
                                                          drawn_box(object.bounds), kRectMarginPx)) {
        into = into.united(*r);
        in_view = true;
      }
    }
    return in_view;
  };
  LayerDrawRequest request;
  PixelRect rect;  // in the output image
  for (const UploadedObject& object : objects_)
    if (object.present && rect_of(object, rect)) request.objects.push_back(&object);
  if (request.objects.empty()) return Drawn::OutOfView;
  const PixelRect objects_rect = rect;  // before the proxies and the shadows' receivers join it
  // Proxies in view go first: those that hide write their depth, so that the objects' fragments
  // behind them fail the depth test before they are shaded; then those that receive shadows but
  // hide nothing, without depth, so that the objects cover them.
  std::vector<const UploadedObject*> receivers_first, occluders;
  PixelRect proxy_receivers;
  for (const UploadedObject& proxy : proxies_) {
    if (!proxy.writes_depth && !proxy.shadow_catcher) continue;  // neither hides nor catches: not drawn
    if (!proxy_at_viewpoint(proxy, ctx.camera.meta.viewpoint)) continue;
    PixelRect r;
    if (!rect_of(proxy, r)) continue;
    if (proxy.shadow_catcher) proxy_receivers = proxy_receivers.united(r);
    (proxy.writes_depth ? occluders : receivers_first).push_back(&proxy);
  }
  request.objects.insert(request.objects.begin(), receivers_first.begin(), receivers_first.end());
  request.objects.insert(request.objects.begin(), occluders.begin(), occluders.end());
  session_->make_current();

  // "map": draw on the pinhole canvas, in the part of it that the output rectangle samples.
  std::shared_ptr<const LensWarpMap> warp;
  if (settings_.lens == LensMode::Map) {
    warp = warp_map(ctx.camera_model);
    if (warp->identity()) warp.reset();  // a pinhole lens: the canvas is the image
  }
  const CameraModel& canvas_camera = warp ? warp->canvas().model() : image_camera;
  request.motion = &motion;
  request.T_cam_world = ctx.pose.T_cam_world;
  request.lens = lens_uniforms(canvas_camera);
  if (eye != Eye::Mono) {
    request.lens.eye = eye;
    request.lens.ods = settings_.ods;
    // The panorama's axis is the world's up through the view camera's centre (panorama_source.h).
    request.lens.ods_up_cam = mat_mul(ctx.pose.T_cam_world.rotation(), Vec3{0, 0, 1});
  }
  request.canvas_camera = &canvas_camera;
  request.rows = {camera.fy(), camera.cy(), camera.height()};
  double angular_diameter_rad = 0;
  request.lighting = frame_lighting(ctx, angular_diameter_rad);
  bool shadow_redrawn = false;
  request.lighting.shadow = shadow_for(ctx, request.lighting, angular_diameter_rad, request.objects, shadow_redrawn);
  pass_times::set_frame_kind(settings_.msaa_samples, request.lighting.shadow != nullptr);
  if (request.lighting.shadow && settings_.shadows.bake_catcher) {
    // Before the footprint, which needs only the part of the catcher its bake says can darken.
    pass_times::start();
    if (!catcher_bake_) catcher_bake_ = std::make_unique<CatcherBake>(session_->layer().color_format() == GL_RGBA16F);
    const UploadedObject& catcher = *request.objects.back();
    const double focal_px = std::max(canvas_camera.fx(), canvas_camera.fy());
    request.lighting.baked_catcher = catcher_bake_->for_frame(
        drawer_->objects(), request.lighting, catcher, catcher_texels_needed(catcher, exposure_poses, focal_px), shadow_redrawn);
    pass_times::mark("catcher bake");
  }
  std::vector<PixelRect> each_shadow_rects;  // per present object, where its shadow can fall; empty: unbounded
  if (request.lighting.shadow) {
    // Where the objects' shadows (and the sky they hide) can fall: the receivers join the
    // footprint only there. The ground catcher's patch spans every object's shadow, so with
    // objects all around the camera it would cover the picture; a proxy's box can be a whole
    // courtyard.
    const std::vector<SE3> seen_from{instants.front().T_cam_world, instants[instants.size() / 2].T_cam_world,
                                     instants.back().T_cam_world};
    PixelRect shadows;
    for (const SE3& T_cam_world : seen_from) {
      // (Not bounded through an eye's offsets: then the receivers whole.)
      const std::optional<std::vector<PixelRect>> r =
          eye == Eye::Mono ? shadow_volume_rects(image_camera, T_cam_world, request.lighting) : std::nullopt;
      // Unbounded (a grazing light): every receiver in view, whole.
      if (!r) {
        shadows = PixelRect::full(camera.width(), camera.height());
        each_shadow_rects.clear();
        break;
      }
      each_shadow_rects.resize(r->size());
      for (size_t i = 0; i < r->size(); ++i) {
        shadows = shadows.united((*r)[i]);
        each_shadow_rects[i] = each_shadow_rects[i].united((*r)[i]);
      }
    }
    rect = rect.united(proxy_receivers.intersected(shadows));
    // The sky occlusion darkens the ground catcher's whole patch (faded at its edge).
    const PixelRect ground_reach =
        settings_.shadows.sky_occlusion ? PixelRect::full(camera.width(), camera.height()) : shadows;
    const UploadedObject& catcher = *request.objects.back();
    if (const std::optional<Bounds> box = catcher_drawn_box(catcher, request.lighting.baked_catcher))
      for (const SE3& T_cam_world : exposure_poses)
        if (std::optional<PixelRect> r =
                projected_box_rect(image_camera, T_cam_world * catcher.T_world_object, drawn_box(*box), kRectMarginPx))
          rect = rect.united(r->intersected(ground_reach));
  }
  if (settings_.full_canvas) rect = PixelRect::full(camera.width(), camera.height());
  request.rect = warp ? warp->canvas_rect_for(rect) : rect;
  // Without sky occlusion the ground catcher darkens only where a shadow falls: it is drawn in
  // each object's shadow rectangle alone, not over the whole footprint between them.
  request.lighting.ground_catcher_rects.reset();
  if (request.lighting.shadow && !settings_.shadows.sky_occlusion && !settings_.full_canvas && !each_shadow_rects.empty()) {
    std::vector<PixelRect> on_canvas;
    for (const PixelRect& r : each_shadow_rects)
      if (!r.empty()) on_canvas.push_back((warp ? warp->canvas_rect_for(r) : r).intersected(request.rect));
    request.lighting.ground_catcher_rects = disjoint_rects(std::move(on_canvas));
  }
  // The ground catcher under the multisampled objects when nothing else is drawn: a proxy that
  // hides must hide the catcher too, which needs the depth the objects' samples hold.
  request.catcher_under = request.lighting.shadow && occluders.empty() && receivers_first.empty();
  if (request.catcher_under) {
    const PixelRect objects_only = settings_.full_canvas ? rect : objects_rect;
    request.objects_rect = (warp ? warp->canvas_rect_for(objects_only) : objects_only).intersected(request.rect);
    // A point on or above the ground and a camera centre on or above it: the segment between them
    // stays above it, so the ground hides nothing of that point. (An eye of a stereo panorama is
    // left to the depth, and so is the full canvas, the path the footprint tests compare against.)
    const double ground_z = request.objects.back()->T_world_object.translation()[2];
    bool above = eye == Eye::Mono && !settings_.full_canvas;
    for (const Instant& instant : instants) {
      above = above && instant.T_cam_world.inverse().translation()[2] >= ground_z;
      for (size_t i = 0; above && i + 1 < request.objects.size(); ++i) {
        const UploadedObject& object = *request.objects[i];
        const SE3 T_world_object = object.pose_at ? object.pose_at(instant.t_ns) : object.T_world_object;
        above = world_box(object.bounds, T_world_object).min[2] >= ground_z;
      }
    }
    request.ground_hides_nothing = above;
  }
  request.image_motion_px = motion.valid() ? std::max(motion.max_image_motion_px, moving_objects_motion_px(motion, image_camera)) : 0;
  request.msaa_samples = settings_.msaa_samples;
  request.rolling_shutter = settings_.rolling_shutter;
  request.occluder_lod_px = settings_.occluder_lod_px;

  LayerReuse::Inputs inputs{ctx.camera_model, exposure_poses, request.objects, request.lighting, shadow_redrawn, rect, eye};
  if (settings_.reuse_layer && reuse_.can_reuse(inputs)) {
    ctx.virtual_layer = reuse_.layer();
    ctx.virtual_layer_drawn = true;
    ctx.blur_method = reuse_.blur_method();
    ctx.blur_samples = reuse_.blur_samples();
    return Drawn::Reused;
  }
  session_->make_current();
  pass_times::start();
  VirtualLayer& layer = session_->layer();
  const LayerDrawResult drawn = drawer_->draw(layer, request, settings_.blur);
  glDisable(GL_SCISSOR_TEST);
  GLuint drawn_texture = drawn.texture;
  if (warp) {
    if (!warp_pass_) warp_pass_ = std::make_unique<LensWarpPass>(layer.color_format());
    warp_pass_->set_map(warp);
    pass_times::start();
    warp_pass_->run(drawn_texture, rect);
    pass_times::mark("lens warp");
    drawn_texture = warp_pass_->texture();
  }
  // The work is queued until something waits for it; waiting here keeps the stage timings honest.
  glFinish();
  check_gl("drawing the virtual layer");
  ctx.virtual_layer = {drawn_texture, camera.width(), camera.height(), rect.x,
                       rect.y,        rect.width,     rect.height,     next_layer_generation()};
  ctx.virtual_layer_drawn = true;
  ctx.blur_method = std::string(blur_method_name(drawn.method));
  ctx.blur_samples = drawn.samples;
  reuse_.remember(std::move(inputs), ctx.virtual_layer, ctx.blur_method, ctx.blur_samples);
  return Drawn::Yes;
}

}  // namespace arpipe

namespace arpipe {

Lighting RenderStage::frame_lighting(const FrameContext& ctx, double& angular_diameter_rad) const {
  Lighting lighting;
  const LightEstimate& light = ctx.light;
  if (!light.scene_linear || light.state == LightState::None) {
    lighting.direction = settings_.light_direction;
    lighting.color = settings_.light_color;
    lighting.ambient = settings_.ambient;
    // The same ambient as radiance: a constant L has L_00 = L sqrt(4 pi) and irradiance / pi = L.
    lighting.radiance_sh[0] = std::sqrt(4 * std::numbers::pi) * settings_.ambient;
    lighting.local = settings_.light_distance_m > 0;
    lighting.position = settings_.light_distance_m * settings_.light_direction;
    // The ground, lit by the light (irradiance / pi = colour x cos) and the sky (L), sends
    // albedo times that; the light's direction from the anchor serves a lamp too.
    lighting.ground_radiance =
        settings_.shadows.ground_albedo *
        (std::max(settings_.light_direction[2], 0.0) * settings_.light_color + settings_.ambient);
    angular_diameter_rad = settings_.shadows.light_angular_diameter_deg * kRadiansPerDegree;
    return lighting;
  }
  // Scene-linear: irradiance over pi multiplies the albedo, and the frame's exposure and gain
  // turn the result into its linear pixel values.
  constexpr double pi = std::numbers::pi;
  lighting.color = {0, 0, 0};
  if (!light.lights.empty() && light.state != LightState::NoDirect) {
    lighting.direction = light.lights.front().direction_world;
    lighting.local = light.lights.front().local;
    lighting.position = light.lights.front().position_world;
    lighting.color = (1 / pi) * light.lights.front().irradiance;
    angular_diameter_rad = light.lights.front().angular_diameter_rad;
  }
  // Further lights have no shadow map: they join the ambient light as the SH of a light from
  // their direction (radiance coefficients E * Y_i(d)), unshadowed.
  ShRgb9 radiance_sh = light.ambient_sh;
  for (size_t k = 1; k < light.lights.size(); ++k)
    sh_add_sample(radiance_sh, light.lights[k].direction_world, light.lights[k].irradiance, 1.0);
  // Convolution with the clamped cosine (Ramamoorthi and Hanrahan), over pi: ambient irradiance / pi
  // from the radiance's coefficients, band by band.
  for (size_t i = 0; i < 9; ++i)
    lighting.ambient_sh[i] = (sh_cosine_lobe_constant(sh_band(int(i))) / pi) * radiance_sh[i];
  lighting.radiance_sh = radiance_sh;
  const double exposure_s = 1e-9 * double(ctx.camera.meta.exposure_ns);
  lighting.exposure_scale = exposure_s > 0 ? exposure_s * ctx.camera.meta.total_gain() : 1.0;
  return lighting;
}

const ShadowLookup* RenderStage::shadow_for(FrameContext& ctx, Lighting& lighting, double angular_diameter_rad,
                                            std::vector<const UploadedObject*>& drawn, bool& redrawn) {
  const auto start = std::chrono::steady_clock::now();
  const auto skip = [&](std::string why) -> const ShadowLookup* {
    ctx.record_timing("shadow", milliseconds_since(start), std::move(why));
    return nullptr;
  };
  if (!shadow_pass_) return skip("shadows off");
  if (norm(lighting.color) <= 0) return skip("no direct light");
  if (std::acos(std::clamp(dot(lighting.direction, shadow_light_direction_), -1.0, 1.0)) > kShadowLightStepRad)
    shadow_light_direction_ = lighting.direction;
  std::vector<ShadowCaster> casters;
  std::vector<const UploadedObject*> caster_objects;
  double extent = 0;
  // The virtual objects and the proxies that cast: the real ones shadow the virtual ones.
  std::vector<const UploadedObject*> real_casters;
  const auto add_caster = [&](const UploadedObject& object) {
    casters.push_back({object.bounds, object.T_world_object});
    caster_objects.push_back(&object);
    extent = std::max(extent, norm(object.bounds.max - object.bounds.min));
  };
  lighting.sky_occluders.clear();
  for (const UploadedObject& object : objects_)
    if (object.present) {
      add_caster(object);
      if (!settings_.shadows.sky_occlusion) continue;
      const Vec3 centre = object.T_world_object * (0.5 * (object.bounds.min + object.bounds.max));
      lighting.sky_occluders.push_back({static_cast<float>(centre[0]), static_cast<float>(centre[1]),
                                        static_cast<float>(centre[2]), static_cast<float>(object.sky_radius_m)});
    }
  const double virtual_extent = extent;
  for (const UploadedObject& proxy : proxies_)
    if (proxy.casts_shadows && proxy_at_viewpoint(proxy, ctx.camera.meta.viewpoint)) {
      add_caster(proxy);
      real_casters.push_back(&proxy);
    }
  // The penumbra of the tallest object, and a little more for the filters' reach.
  const double margin = extent * (std::tan(angular_diameter_rad) + 0.05);
  std::optional<ShadowFrustum> frustum =
      lighting.local
          ? fit_local_shadow_frustum(lighting.position, casters, settings_.shadows.receiver_height_m, margin)
          : fit_shadow_frustum(shadow_light_direction_, casters, settings_.shadows.receiver_height_m, margin);
  if (!frustum) return skip(lighting.local ? "lamp not above the objects" : "light below the ground");
  // The ground catcher covers where the virtual objects' shadows fall; the real casters' own
  // shadows are in the picture already, so they widen the map but not the catcher.
  ReceiverPatch patch = frustum->receiver;
  if (!real_casters.empty()) {
    const std::vector<ShadowCaster> virtual_casters(casters.begin(), casters.end() - long(real_casters.size()));
    // Widened by the virtual objects' own penumbra: a large real caster (a whole courtyard) must
    // not spread the catcher, and with it the footprint, over the picture.
    const double virtual_margin = virtual_extent * (std::tan(angular_diameter_rad) + 0.05);
    const std::optional<ShadowFrustum> virtual_only =
        lighting.local
            ? fit_local_shadow_frustum(lighting.position, virtual_casters, settings_.shadows.receiver_height_m, virtual_margin)
            : fit_shadow_frustum(shadow_light_direction_, virtual_casters, settings_.shadows.receiver_height_m, virtual_margin);
    if (virtual_only) {
      patch = virtual_only->receiver;
      // The maps are read only on the virtual objects and where their shadows fall: across the
      // light, the column over those (a courtyard of proxies would otherwise spread the map's
      // texels, and with them the filters' reach, over the whole courtyard). Along it, as far as
      // the proxies reach into that column, cluster by cluster (a floor adds its patch under the
      // column, not its whole extent: the PCSS search widens with the depth range), so that a real
      // caster anywhere up the column still shades them.
      if (!lighting.local) {
        ShadowFrustum narrowed = *virtual_only;
        for (const UploadedObject& proxy : proxies_) {
          // The receivers too: one beyond the far end would read as lit.
          if (!(proxy.casts_shadows || proxy.shadow_catcher) || !proxy_at_viewpoint(proxy, ctx.camera.meta.viewpoint))
            continue;
          if (proxy.cluster_bounds.empty()) extend_depth_over(narrowed, world_box(proxy.bounds, proxy.T_world_object));
          for (const Bounds& cluster : proxy.cluster_bounds)
            extend_depth_over(narrowed, world_box(cluster, proxy.T_world_object));
        }
        const double slack = 1e-3 * std::max(narrowed.max[2] - narrowed.min[2], 1e-3);
        narrowed.min[2] -= slack;
        narrowed.max[2] += slack;
        frustum = narrowed;
      }
    }
  }
  // The sky occlusion reaches further than the shadow: a sphere of radius r whose centre stands c
  // above the ground hides r^2 c / d^3 of its sky at distance d (1 % at d = 4 r). Growing the patch
  // that far would spread the footprint over most of the picture; it grows by 2 r, and the
  // occlusion fades out towards its edge (render/object_renderer.cpp).
  for (const std::array<float, 4>& sphere : lighting.sky_occluders)
    for (size_t axis = 0; axis < 2; ++axis) {
      patch.min[axis] = std::min(patch.min[axis], double(sphere[axis]) - 2.0 * sphere[3]);
      patch.max[axis] = std::max(patch.max[axis], double(sphere[axis]) + 2.0 * sphere[3]);
    }
  lighting.catcher_patch = {static_cast<float>(patch.min[0]), static_cast<float>(patch.min[1]),
                            static_cast<float>(patch.max[0]), static_cast<float>(patch.max[1])};
  const UploadedObject& catcher = receiver_->over(patch);
  // Variance maps also hold the ground, so that filtering across an object's edge blends its depth
  // with the ground's rather than with empty space.
  if (is_variance_method(settings_.shadow_method)) caster_objects.push_back(&catcher);
  bool drew = shadow_pass_->render(*frustum, caster_objects, angular_diameter_rad);
  lighting.real_shadow = nullptr;
  if (real_shadow_pass_ && !real_casters.empty()) {
    if (is_variance_method(settings_.shadow_method)) real_casters.push_back(&catcher);  // as in the main map
    drew = real_shadow_pass_->render(*frustum, real_casters, angular_diameter_rad) || drew;
    lighting.real_shadow = &real_shadow_pass_->lookup();
  }
  drawn.push_back(&catcher);
  shadow_filter_reach_m_ = shadow_lookup_reach_m(shadow_pass_->lookup(), *frustum);
  lighting.unshadowed = unshadowed_objects(caster_objects, *frustum, settings_.shadow_method, shadow_filter_reach_m_);
  redrawn = drew;
  if (drew) glFinish();  // honest timings: the work is queued until something waits
  ctx.record_timing("shadow", milliseconds_since(start), drew ? "" : "reused");
  return &shadow_pass_->lookup();
}

}  // namespace arpipe

namespace arpipe {

bool RenderStage::move_objects(const ShutterMotion& motion) {
  const int64_t start = motion.timing.exposure_start_ns, end = motion.timing.end_ns();
  physics_->advance(start, end);
  bool moved = false;
  const ScenePhysics* physics = physics_.get();
  for (size_t i = 0; i < objects_.size(); ++i) {
    const std::optional<BodySample> mid = physics->sample(i, start + (end - start) / 2);
    if (!mid) continue;
    UploadedObject& object = objects_[i];
    moved = moved || !(mid->T_world_body.translation() == object.T_world_object.translation() &&
                       mid->T_world_body.rotation() == object.T_world_object.rotation()) ||
            mid->present != object.present;
    object.T_world_object = mid->T_world_body;
    object.present = mid->present;
    object.pose_at = [physics, i](int64_t t) {
      const std::optional<BodySample> sample = physics->sample(i, t);
      return sample ? sample->T_world_body : SE3::identity();
    };
  }
  return moved;
}

std::optional<std::vector<PixelRect>> RenderStage::shadow_volume_rects(const CameraModel& camera, const SE3& T_cam_world,
                                                                      const Lighting& lighting) const {
  // Each object's shadow lies in the hull of its box and the box's projection onto the ground
  // along the light (the sweep), and the shadow lookups near it read it from up to the filter's
  // reach away: the sweep grown by a square that holds that reach. With sky occlusion, the
  // square of the ground it darkens too (render/object_renderer.cpp: 2 r about its centre). Sampled
  // for the lens's bend, and cut at the near plane, so that an object beside or behind the camera
  // bounds only the part of its shadow in front of it.
  constexpr int kSamples = 8;
  constexpr int kOutlineSamples = 16;  // an outline edge spans several of the sum's edges
  // Down to the ground, or to the lowest shadow-catching proxy below it: a proxy's part under the
  // real floor shows where the floor is no proxy (the ground catcher draws no depth before it),
  // and catches the shadow further along the light.
  double h = settings_.shadows.receiver_height_m;
  for (const UploadedObject& proxy : proxies_)
    if (proxy.shadow_catcher)
      for (const Vec3& corner : box_corners(proxy.bounds)) h = std::min(h, (proxy.T_world_object * corner)[2]);
  std::vector<PixelRect> rects;
  std::vector<Vec3> points;
  for (const UploadedObject& object : objects_) {
    if (!object.present) continue;
    points.clear();
    PixelRect& rect = rects.emplace_back();
    const std::array<Vec3, 8> local = box_corners(object.bounds);
    // The penumbra, or the shadow filter's own reach when the map's texels are coarser (a map
    // fitted around large real casters).
    const double reach = std::max(norm(object.bounds.max - object.bounds.min) * 0.1 + 0.01, shadow_filter_reach_m_);
    std::array<Vec3, 8> corners{}, towards{};
    double lowest_sin = 1;  // of the light's elevation over the corners
    for (size_t i = 0; i < 8; ++i) {
      corners[i] = object.T_world_object * local[i];
      towards[i] = lighting.local ? normalized(lighting.position - corners[i]) : lighting.direction;
      if (towards[i][2] < 0.05) return std::nullopt;  // grazing light: the shadow runs far
      lowest_sin = std::min(lowest_sin, towards[i][2]);
    }
    // The reach is across the light, a square window of the map (the diagonal sqrt 2 times as far);
    // on the ground it stretches by up to 1 / sin of the light's elevation. A square of that
    // half-width holds the disc it can reach.
    const double r = std::sqrt(2.0) * reach / lowest_sin;
    const std::array<Vec3, 4> square{Vec3{r, r, 0}, Vec3{-r, r, 0}, Vec3{-r, -r, 0}, Vec3{r, -r, 0}};
    // The sweep's 16 vertices: the box's corners (0-7) and their shadows on the ground (8-15), world.
    std::array<Vec3, 16> sweep{};
    for (size_t i = 0; i < 8; ++i) {
      sweep[i] = corners[i];
      sweep[8 + i] = corners[i] - ((corners[i][2] - h) / towards[i][2]) * towards[i];
    }
    // With sky occlusion, the ground square it darkens too: 2 r about the object's centre.
    std::vector<Vec3> darkened;
    if (settings_.shadows.sky_occlusion) {
      const Vec3 centre = object.T_world_object * (0.5 * (object.bounds.min + object.bounds.max));
      const double half = 2 * object.sky_radius_m;
      for (size_t i = 0; i < 4; ++i)
        darkened.push_back(Vec3{centre[0] + ((i == 1 || i == 2) ? half : -half), centre[1] + (i >= 2 ? half : -half), h});
    }
    // The sum of the sweep and the square lies in the convex hull of its 64 vertices (each sweep
    // vertex moved to each of the square's corners), and so does the sky occlusion's square: when
    // all lie in front of the near plane, the outline of that hull bounds it (a tenth of the
    // points of the edges below, each projected through the lens).
    std::vector<Vec3> vertices;
    for (const Vec3& vertex : sweep)
      for (const Vec3& shift : square) vertices.push_back(T_cam_world * (vertex + shift));
    for (const Vec3& corner : darkened) vertices.push_back(T_cam_world * corner);
    if (!append_pinhole_outline(points, vertices, kOutlineSamples)) {
      // Some reach behind the near plane: the sum's edges cut there, each of the sweep's edges
      // moved to each of the square's corners, and the square's edges placed at each of the
      // sweep's vertices; and the darkened square's edges.
      const auto edge = [&](const Vec3& a, const Vec3& b) {
        append_segment_in_front(points, T_cam_world * a, T_cam_world * b, kSamples);
      };
      for (const Vec3& shift : square)
        for (size_t a = 0; a < 8; ++a) {
          edge(sweep[a] + shift, sweep[8 + a] + shift);
          for (size_t bit = 1; bit < 8; bit <<= 1) {
            if (a & bit) continue;
            edge(sweep[a] + shift, sweep[a | bit] + shift);
            edge(sweep[8 + a] + shift, sweep[8 + (a | bit)] + shift);
          }
        }
      for (const Vec3& vertex : sweep)
        for (size_t k = 0; k < 4; ++k) edge(vertex + square[k], vertex + square[(k + 1) % 4]);
      for (size_t i = 0; i < darkened.size(); ++i) edge(darkened[i], darkened[(i + 1) % darkened.size()]);
    }
    // Object by object: the hull is convex, their union is not (one beside the camera on the left
    // and one on the right would span the picture). Behind the camera or out of the picture: none.
    if (const std::optional<PixelRect> drawn = projected_points_rect(camera, points, kRectMarginPx)) rect = *drawn;
  }
  return rects;
}

double RenderStage::moving_objects_motion_px(const ShutterMotion& motion, const CameraModel& camera) const {
  // The length of each box corner's image path over the exposure, in kExposureInstants pieces: a
  // ball that bounces within the exposure travels far though it ends near where it started.
  double most = 0;
  const int64_t start = motion.timing.exposure_start_ns, span = motion.timing.end_ns() - start;
  for (const UploadedObject& object : objects_) {
    if (!object.pose_at || !object.present) continue;
    std::array<double, 8> length{};
    std::array<std::optional<Vec2>, 8> previous{};
    for (int k = 0; k <= kExposureInstants; ++k) {
      const int64_t t = start + span * k / kExposureInstants;
      const SE3 T_cam_object = motion.T_cam_world_at(t) * object.pose_at(t);
      const std::array<Vec3, 8> corners = box_corners(object.bounds);
      for (size_t c = 0; c < corners.size(); ++c) {
        const std::optional<Vec2> p = camera.project(T_cam_object * corners[c]);
        if (p && previous[c]) length[c] += std::hypot((*p)[0] - (*previous[c])[0], (*p)[1] - (*previous[c])[1]);
        previous[c] = p;
      }
    }
    most = std::max(most, *std::max_element(length.begin(), length.end()));
  }
  return most;
}

}  // namespace arpipe
