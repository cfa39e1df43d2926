// The share of each virtual object the proxies hide (see occlusion_meter.h).
#include "render/occlusion_meter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>

namespace arpipe {
namespace {

// A mesh's ray scene with its placement for this frame: rays go into its frame (scale included,
// so that t stays the same) with the inverse computed once per frame, not once per ray.
struct PlacedScene {
  const PrtRayScene* scene = nullptr;
  SE3 T_object_world;
  double inverse_scale = 1;

  PlacedScene(const PrtRayScene* s, const UploadedObject& object)
      : scene(s), T_object_world(object.T_world_object.inverse()), inverse_scale(1 / object.scale) {}
  std::optional<float> hit_distance(const Vec3& origin, const Vec3& dir) const {
    const PrtRayHit hit =
        scene->closest_hit(inverse_scale * (T_object_world * origin), inverse_scale * T_object_world.rotate(dir));
    if (!hit.hit) return std::nullopt;
    return hit.t;
  }
};

}  // namespace

OcclusionMeter::OcclusionMeter(const Config& config, const LoadedMeshes& meshes) {
  std::map<size_t, std::shared_ptr<const PrtRayScene>> by_mesh;
  for (size_t i = 0; i < config.render.objects.size() && i < meshes.mesh_of_object.size(); ++i) {
    const size_t m = meshes.mesh_of_object[i];
    auto found = by_mesh.find(m);
    if (found == by_mesh.end()) found = by_mesh.emplace(m, std::make_shared<const PrtRayScene>(meshes.meshes[m].mesh)).first;
    object_scenes_.push_back(found->second);
  }
  for (size_t i = 0; i < meshes.proxies.size(); ++i)
    proxy_scenes_.push_back(config.render.proxies[i].roles.occlude ? std::make_shared<const PrtRayScene>(*meshes.proxies[i].mesh)
                                                                  : nullptr);
}

OcclusionMeter::~OcclusionMeter() = default;

std::vector<ObjectReport> OcclusionMeter::measure(const CameraModel& camera, const SE3& T_cam_world,
                                                  const std::vector<UploadedObject>& objects,
                                                  const std::vector<UploadedObject>& proxies,
                                                  const std::optional<int>& viewpoint, Eye eye, const OdsRig& rig) const {
  std::vector<ObjectReport> reports;
  const SE3 T_world_cam = T_cam_world.inverse();
  const Vec3 origin = T_world_cam.translation();
  const double fx = camera.fx(), fy = camera.fy(), cx = camera.cx(), cy = camera.cy();
  std::vector<std::optional<PlacedScene>> occluders;
  for (size_t p = 0; p < proxies.size() && p < proxy_scenes_.size(); ++p)
    occluders.push_back(proxy_scenes_[p] && proxy_at_viewpoint(proxies[p], viewpoint)
                            ? std::optional<PlacedScene>(std::in_place, proxy_scenes_[p].get(), proxies[p])
                            : std::nullopt);
  for (size_t i = 0; i < objects.size() && i < object_scenes_.size(); ++i) {
    const UploadedObject& object = objects[i];
    ObjectReport report;
    report.index = static_cast<int>(i);
    report.position_m = object.T_world_object.translation();
    report.present = object.present;
    // The box's extent in the pinhole core, clipped to the picture; corners behind the camera
    // leave the box unmeasured (it is then mostly out of view). An eye of a stereo panorama draws
    // each point moved by less than ipd / 2: the box grown by that holds it.
    double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
    bool behind = false;
    const double grow = eye == Eye::Mono ? 0.0 : 0.5 * rig.ipd_m;
    const Bounds box{object.bounds.min - Vec3{grow, grow, grow}, object.bounds.max + Vec3{grow, grow, grow}};
    for (const Vec3& corner : box_corners(box)) {
      const Vec3 p = T_cam_world * (object.T_world_object * corner);
      if (p[2] <= 1e-6) {
        behind = true;
        break;
      }
      const double u = fx * p[0] / p[2] + cx, v = fy * p[1] / p[2] + cy;
      u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
    }
    u0 = std::max(u0, -0.5), v0 = std::max(v0, -0.5);
    u1 = std::min(u1, camera.width() - 0.5), v1 = std::min(v1, camera.height() - 0.5);
    report.in_view = object.present && !behind && u1 > u0 && v1 > v0;
    if (report.in_view) {
      const PlacedScene placed(object_scenes_[i].get(), object);
      int met = 0;
      std::vector<int> hidden_by(proxies.size(), 0);
      for (int gy = 0; gy < kGrid; ++gy)
        for (int gx = 0; gx < kGrid; ++gx) {
          const double u = u0 + (gx + 0.5) * (u1 - u0) / kGrid, v = v0 + (gy + 0.5) * (v1 - v0) / kGrid;
          const Vec3 dir = T_world_cam.rotate(Vec3{(u - cx) / fx, (v - cy) / fy, 1.0});
          const Vec3 from = eye == Eye::Mono ? origin : origin + ods_eye_origin(rig, eye, Vec3{0, 0, 1}, normalized(dir));
          const std::optional<float> t_object = placed.hit_distance(from, dir);
          if (!t_object) continue;
          ++met;
          float nearest = *t_object;
          std::optional<size_t> by;
          for (size_t p = 0; p < occluders.size(); ++p) {
            if (!occluders[p]) continue;
            const std::optional<float> t_proxy = occluders[p]->hit_distance(from, dir);
            if (t_proxy && *t_proxy < nearest) nearest = *t_proxy, by = p;
          }
          if (by) ++hidden_by[*by];
        }
      if (met > 0) {
        int hidden = 0;
        for (size_t p = 0; p < proxies.size(); ++p) {
          hidden += hidden_by[p];
          if (hidden_by[p] > 0) report.hidden_by.emplace_back(proxies[p].name, double(hidden_by[p]) / met);
        }
        report.hidden = double(hidden) / met;
      }
    }
    reports.push_back(std::move(report));
  }
  return reports;
}

}  // namespace arpipe
