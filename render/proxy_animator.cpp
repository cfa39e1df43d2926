// Proxies that follow a glTF animation (see proxy_animator.h).
#include "render/proxy_animator.h"

#include <cmath>

namespace arpipe {
namespace {

// scale > 0 keeps min below max.
Bounds times(const Bounds& box, double scale) { return Bounds{scale * box.min, scale * box.max}; }

}  // namespace

ScaledPose compose(const SE3& T_config, double config_scale, const ScaledPose& node) {
  const SE3 pose(mat_mul(T_config.rotation(), node.pose.rotation()),
                 T_config.translation() + config_scale * T_config.rotate(node.pose.translation()));
  return ScaledPose{pose, config_scale * node.scale};
}

ProxyAnimator::ProxyAnimator(const Config& config, const LoadedMeshes& loaded, const std::vector<UploadedObject>& proxies) {
  for (size_t i = 0; i < loaded.proxies.size() && i < proxies.size() && i < config.render.proxies.size(); ++i) {
    const LoadedMeshes::Proxy& entry = loaded.proxies[i];
    if (!entry.animation) continue;
    const UploadedObject& proxy = proxies[i];
    const double to_unscaled = 1 / proxy.scale;
    Animated a{i, proxy_placement(config.render.proxies[i]), config.render.proxies[i].scale, entry.animation,
               entry.animation_node, times(proxy.bounds, to_unscaled), {}, {}};
    for (const Bounds& b : proxy.cluster_bounds) a.cluster_bounds.push_back(times(b, to_unscaled));
    for (double e : proxy.occluder_level_errors_m) a.occluder_level_errors_m.push_back(e * to_unscaled);
    animated_.push_back(std::move(a));
  }
}

bool ProxyAnimator::place(std::vector<UploadedObject>& proxies, std::optional<int64_t> t_ns, AnimationReport& report) {
  const int64_t t = t_ns.value_or(0);
  report.time_s = 1e-9 * double(t);
  report.proxies.clear();
  const bool moved = placed_at_ns_ != t;
  for (const Animated& a : animated_) {
    UploadedObject& proxy = proxies.at(a.index);
    if (moved) {
      const ScaledPose placed = compose(a.T_config, a.config_scale, a.animation->node_pose_at(a.node, report.time_s));
      proxy.T_world_object = placed.pose;
      proxy.scale = placed.scale;
      proxy.bounds = times(a.bounds, placed.scale);
      for (size_t c = 0; c < a.cluster_bounds.size() && c < proxy.cluster_bounds.size(); ++c)
        proxy.cluster_bounds[c] = times(a.cluster_bounds[c], placed.scale);
      for (size_t l = 0; l < a.occluder_level_errors_m.size() && l < proxy.occluder_level_errors_m.size(); ++l)
        proxy.occluder_level_errors_m[l] = a.occluder_level_errors_m[l] * placed.scale;
    }
    report.proxies.push_back(
        {proxy.name, proxy.T_world_object.translation(), proxy.T_world_object.rotation_vector(), proxy.scale});
  }
  placed_at_ns_ = t;
  return moved;
}

}  // namespace arpipe
