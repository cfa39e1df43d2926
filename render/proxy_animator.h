// Proxies that follow a glTF animation (render.proxies[].node of an animated file, seed 003: the
// phantoms of a pre-rendered video's moving objects), placed at each frame's time on the source's
// own timeline (FrameMetadata::source_frame_time_ns: a panorama video's frame index over its rate).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/pipeline/object_report.h"
#include "core/scene/gltf_animation.h"
#include "render/uploaded_objects.h"

namespace arpipe {

// x -> T_config (config_scale * node(x)): a node's place in its file, then the proxy's placement.
ScaledPose compose(const SE3& T_config, double config_scale, const ScaledPose& node);

class ProxyAnimator {
 public:
  // The animated ones among `proxies` (uploaded from this config and these meshes, in config order):
  // those whose node the file's animation moves. Their bounds are kept unscaled, to scale again
  // when the animation scales the node.
  ProxyAnimator(const Config& config, const LoadedMeshes& loaded, const std::vector<UploadedObject>& proxies);
  bool empty() const { return animated_.empty(); }

  // Places the animated proxies at `t_ns` on the animation's timeline (nullopt: a frame without a
  // source timeline, shown at the animation's start); true when one of them moved since the last
  // call. `report` lists where each stands.
  bool place(std::vector<UploadedObject>& proxies, std::optional<int64_t> t_ns, AnimationReport& report);

 private:
  struct Animated {
    size_t index;  // in proxies
    SE3 T_config;
    double config_scale;
    std::shared_ptr<const GltfAnimation> animation;
    int node;
    Bounds bounds;                        // unscaled
    std::vector<Bounds> cluster_bounds;   // unscaled
    std::vector<double> occluder_level_errors_m;  // unscaled
  };
  std::vector<Animated> animated_;
  std::optional<int64_t> placed_at_ns_;  // none until the first frame
};

}  // namespace arpipe
