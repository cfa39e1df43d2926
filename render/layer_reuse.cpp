// Whether the last virtual layer can be shown again (see layer_reuse.h).
#include "render/layer_reuse.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/uploaded_objects.h"

namespace arpipe {
namespace {

constexpr double kNearestDepthM = 1e-3;  // corners nearer than this (or behind) forbid a bound

double largest_light_value(const Lighting& l) {
  double largest = 0;
  const auto take = [&](const Vec3& v) {
    for (double c : v) largest = std::max(largest, std::abs(c));
  };
  take(l.color);
  take(l.ambient);
  take(l.ground_radiance);
  for (const Vec3& c : l.ambient_sh) take(c);
  for (const Vec3& c : l.radiance_sh) take(c);
  return largest;
}

}  // namespace

bool same_light(const Lighting& a, const Lighting& b) {
  if (a.local != b.local || a.shadow != b.shadow) return false;
  if (std::acos(std::clamp(dot(a.direction, b.direction), -1.0, 1.0)) > LayerReuse::kMaxLightTurnRad) return false;
  const double tolerance = LayerReuse::kMaxLightChange * std::max(largest_light_value(a), largest_light_value(b));
  const auto close = [&](const Vec3& x, const Vec3& y) {
    for (int i = 0; i < 3; ++i)
      if (std::abs(x[i] - y[i]) > tolerance) return false;
    return true;
  };
  if (!close(a.color, b.color) || !close(a.ambient, b.ambient) || !close(a.ground_radiance, b.ground_radiance)) return false;
  for (size_t i = 0; i < a.ambient_sh.size(); ++i)
    if (!close(a.ambient_sh[i], b.ambient_sh[i]) || !close(a.radiance_sh[i], b.radiance_sh[i])) return false;
  // A lamp's place: the same turn as the direction, seen from a metre.
  return !(a.local && norm(a.position - b.position) > LayerReuse::kMaxLightTurnRad);
}

namespace {

bool same_exposure(const Lighting& a, const Lighting& b) {
  const double scale = std::max(std::abs(a.exposure_scale), std::abs(b.exposure_scale));
  return std::abs(a.exposure_scale - b.exposure_scale) <= LayerReuse::kMaxLightChange * scale;
}

}  // namespace

double max_corner_motion_px(const CameraModel& camera, const std::vector<const UploadedObject*>& objects,
                            const SE3& T_cam_world_a, const SE3& T_cam_world_b) {
  const double focal = std::max(camera.fx(), camera.fy());
  double most = 0;
  for (const UploadedObject* object : objects) {
    const SE3 a = T_cam_world_a * object->T_world_object, b = T_cam_world_b * object->T_world_object;
    for (const Vec3& corner : box_corners(object->bounds)) {
      const Vec3 pa = a * corner, pb = b * corner;
      const double depth = std::min(pa[2], pb[2]);
      if (depth < kNearestDepthM) {
        if (pa == pb) continue;  // the same point: it does not move, wherever it is
        return std::numeric_limits<double>::infinity();
      }
      // u = f x / z: |du| <= f (|dx| + |x / z| |dz|) / z, with the larger off-axis slope of the two.
      const double slope = std::max(std::hypot(pa[0], pa[1]) / std::max(pa[2], kNearestDepthM),
                                    std::hypot(pb[0], pb[1]) / std::max(pb[2], kNearestDepthM));
      const Vec3 d = pb - pa;
      most = std::max(most, focal * (std::hypot(d[0], d[1]) + slope * std::abs(d[2])) / depth);
    }
  }
  return most;
}

bool LayerReuse::can_reuse(const Inputs& now) const {
  if (!have_last_ || now.shadow_map_redrawn) return false;
  if (now.camera_model != last_.camera_model || now.objects != last_.objects || now.rect != last_.rect ||
      now.eye != last_.eye)
    return false;
  if (now.exposure_poses.size() != last_.exposure_poses.size()) return false;
  for (size_t k = 0; k < now.exposure_poses.size(); ++k)
    if (max_corner_motion_px(*now.camera_model, now.objects, last_.exposure_poses[k], now.exposure_poses[k]) >
        kMaxMotionPx)
      return false;
  return same_light(now.lighting, last_.lighting) && same_exposure(now.lighting, last_.lighting);
}

void LayerReuse::remember(Inputs inputs, const VirtualLayerTexture& layer, std::string blur_method, int blur_samples) {
  last_ = std::move(inputs);
  layer_ = layer;
  blur_method_ = std::move(blur_method);
  blur_samples_ = blur_samples;
  have_last_ = true;
}

}  // namespace arpipe
