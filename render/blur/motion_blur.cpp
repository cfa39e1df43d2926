// Draws one frame's virtual objects, sharp or motion blurred (see motion_blur.h).
#include "render/blur/motion_blur.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/motion/intraframe_warp_plan.h"
#include "render/gl/gl_error.h"
#include "render/gl/pass_times.h"
#include "render/gl/render_errors.h"

namespace arpipe {
namespace {

// Automatic sample counts: about one per pixel of image motion, so neighbouring samples overlap
// (gaps would show as separate ghosts), within what each method can afford.
constexpr int kMaxAutoAccumulateSamples = 64;
constexpr int kMaxAutoVelocityTaps = 32;

int samples_for_motion(double motion_px, int lowest, int highest) {
  return std::clamp(static_cast<int>(std::ceil(motion_px)), lowest, highest);
}

std::vector<ObjectAtInstant> objects_at(const LayerDrawRequest& request, double exposure_fraction) {
  static const ShutterMotion kNoMotion;
  const ShutterMotion& motion = request.motion ? *request.motion : kNoMotion;
  std::vector<ObjectAtInstant> out;
  out.reserve(request.objects.size());
  for (const UploadedObject* object : request.objects)
    out.push_back({object, row_poses(motion, request.T_cam_world, object->T_world_object, exposure_fraction,
                                     request.rolling_shutter, object->pose_at)});
  return out;
}

}  // namespace

MotionBlurDrawer::MotionBlurDrawer(const EglContext& context, GLenum layer_format)
    : context_(context), layer_format_(layer_format) {}

void MotionBlurDrawer::prepare(BlurMethod method) {
  if (method == BlurMethod::Accumulate && !accumulation_) accumulation_ = std::make_unique<AccumulationPass>(context_);
  if (method == BlurMethod::IntraframeWarp && !seed_) seed_ = std::make_unique<IntraframeWarpBlurPass>(layer_format_);
  if (method == BlurMethod::Velocity && !velocity_) velocity_ = std::make_unique<VelocityBlurPass>(layer_format_);
}

void MotionBlurDrawer::draw_at(VirtualLayer& layer, const LayerDrawRequest& request, double exposure_fraction) {
  const std::vector<ObjectAtInstant> objects = objects_at(request, exposure_fraction);
  pass_times::start();
  if (!request.catcher_under || layer.samples() <= 1 || objects.empty()) {
    layer.begin(request.rect);
    pass_times::mark("clear");
    objects_.draw(request.lens, request.rows, request.lighting, objects, request.rect, request.occluder_lod_px);
    pass_times::mark("objects");
    layer.resolve(request.rect);
    pass_times::mark("resolve");
    return;
  }
  // Multisampled only where the objects reach, in an image of that area alone; the catcher's wide
  // patch after it, at one sample per pixel.
  layer.begin_objects(objects_area_, request.objects_rect);
  pass_times::mark("clear");
  const std::span<const ObjectAtInstant> without_catcher(objects.data(), objects.size() - 1);
  if (!request.ground_hides_nothing) objects_.draw_ground_catcher_depth(request.lens, request.rows, objects.back());
  objects_.draw(request.lens, request.rows, request.lighting, without_catcher, request.objects_rect,
                request.occluder_lod_px);
  pass_times::mark("objects");
  layer.resolve_objects(request.rect);
  pass_times::mark("resolve and copy");
  layer.begin_resolved(request.rect);
  objects_.draw_ground_catcher_under(request.lens, request.rows, request.lighting, objects.back(), request.rect);
  pass_times::mark("catcher");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

LayerDrawResult MotionBlurDrawer::draw(VirtualLayer& layer, const LayerDrawRequest& request, const BlurConfig& config) {
  layer.ensure(request.lens.width, request.lens.height, request.msaa_samples);
  if (request.catcher_under && layer.samples() > 1) {
    // Once a frame, for every draw of it (the blur methods draw the objects several times).
    objects_area_ = objects_area_chooser_.choose(request.objects_rect, request.lens.width, request.lens.height);
    if (objects_area_.width <= 0) throw RenderError("the objects' rectangle lies outside the canvas");
  }
  const BlurMethod method = config.method;
  LayerDrawResult result;
  if (method != BlurMethod::Off) {
    if (!request.motion || !request.motion->valid()) result.sharp_because = "no motion estimate";
    else if (request.image_motion_px < config.min_motion_px) result.sharp_because = "motion below render.blur.min_motion_px";
  }
  if (method != BlurMethod::Off && result.sharp_because.empty()) {
    prepare(method);
    switch (method) {
      case BlurMethod::Accumulate:
        return draw_accumulated(layer, request,
                                config.samples > 0 ? config.samples
                                                   : samples_for_motion(request.image_motion_px, 2, kMaxAutoAccumulateSamples));
      case BlurMethod::IntraframeWarp: return draw_intraframe_warp(layer, request, config.samples);
      case BlurMethod::Velocity:
        return draw_velocity(layer, request,
                             config.samples > 0 ? std::min(config.samples, VelocityBlurPass::kMaxSamples)
                                                : samples_for_motion(request.image_motion_px, 4, kMaxAutoVelocityTaps));
      case BlurMethod::Off: break;
    }
  }
  // Sharp: each row at the middle of its own exposure.
  draw_at(layer, request, 0.5);
  result.texture = layer.texture();
  return result;
}

LayerDrawResult MotionBlurDrawer::draw_accumulated(VirtualLayer& layer, const LayerDrawRequest& request, int samples) {
  accumulation_->begin(layer.width(), layer.height(), request.rect);
  const float weight = 1.0f / static_cast<float>(samples);
  for (int k = 0; k < samples; ++k) {
    // Midpoints of equal slices: a box filter over the shutter interval.
    draw_at(layer, request, (k + 0.5) / samples);
    accumulation_->add(layer.texture(), request.rect, weight);
  }
  return {accumulation_->texture(), BlurMethod::Accumulate, samples, {}};
}

LayerDrawResult MotionBlurDrawer::draw_intraframe_warp(VirtualLayer& layer, const LayerDrawRequest& request, int fixed_samples) {
  // The box corners of every object, tracked on the canvas: one affine warp serves all objects,
  // which is exact for one object and close for objects near each other.
  // Proxies stand still in the world like the ground; their (often large, near) boxes would pull
  // the one warp away from the objects' own motion, so only the rest are tracked.
  const CornerTrack corners_at = [&](double t) {
    std::vector<std::optional<Vec2>> out;
    for (const ObjectAtInstant& item : objects_at(request, t))
      if (!item.object->proxy)
        for (const Vec3& corner : box_corners(item.object->bounds))
          out.push_back(request.canvas_camera->project(item.poses.camera_point(corner, request.rows)));
    return out;
  };
  const IntraframeWarpPlan plan = plan_intraframe_warp_blur(corners_at, fixed_samples);
  if (plan.samples.empty()) {
    draw_at(layer, request, 0.5);
    return {layer.texture(), BlurMethod::Off, 0, "no box corner in view"};
  }
  draw_at(layer, request, kFirstIntraframe);
  first_intraframe_.ensure(layer.color_format(), layer.width(), layer.height(), false);
  first_intraframe_.copy_from(layer.resolved_framebuffer(), request.rect);
  pass_times::mark("intraframe copy");
  draw_at(layer, request, kSecondIntraframe);
  pass_times::start();
  seed_->run(first_intraframe_.texture(), layer.texture(), layer.width(), layer.height(), plan, request.rect);
  pass_times::mark("seed blur");
  return {seed_->texture(), BlurMethod::IntraframeWarp, static_cast<int>(plan.samples.size()), {}};
}

LayerDrawResult MotionBlurDrawer::draw_velocity(VirtualLayer& layer, const LayerDrawRequest& request, int samples) {
  draw_at(layer, request, 0.5);
  std::vector<ObjectOverExposure> objects;
  const std::vector<ObjectAtInstant> start = objects_at(request, 0), mid = objects_at(request, 0.5),
                                     end = objects_at(request, 1);
  for (size_t i = 0; i < request.objects.size(); ++i)
    objects.push_back({request.objects[i], start[i].poses, mid[i].poses, end[i].poses});
  velocity_image_.ensure(GL_RGBA16F, layer.width(), layer.height(), true);
  velocity_image_.begin(request.rect);
  objects_.draw_velocity(request.lens, request.rows, objects);
  velocity_->run(layer.texture(), velocity_image_.texture(), layer.width(), layer.height(), request.rect, samples);
  return {velocity_->texture(), BlurMethod::Velocity, samples, {}};
}

}  // namespace arpipe
