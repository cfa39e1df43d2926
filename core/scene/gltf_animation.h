// A glTF 2.0 file's node animation (glTF "animations": translation, rotation and scale channels of
// nodes, STEP, LINEAR or CUBICSPLINE), sampled at any time: where an animated proxy stands and
// where the file's KHR_lights_punctual lights are at a video frame's time (seed 003: the proxies
// follow the pre-rendered video's animation). Frames as gltf_loader.h: glTF's y-up axes turned
// into arpipe's z-up object frame.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"
#include "core/scene/gltf_loader.h"

namespace arpipe {

// A rigid placement with a uniform scale: x -> pose * (scale * x).
struct ScaledPose {
  SE3 pose;
  double scale = 1.0;
};

class GltfAnimation {
 public:
  // Reads `path` with the checks of load_gltf_mesh (gltf_document.h, gltf_limits.h) and the
  // animation named `animation` ("": the file's first; a file without animations, or "" on a file
  // that has none, gives every node at rest with duration 0). Throws AssetError naming the file and
  // the place (animation, channel, sampler, accessor) for: an animation name not in the file, a
  // channel whose node does not exist, a sampler index out of range, input times not finite,
  // negative or not strictly increasing, output values not finite or not as many as the input's
  // (three times as many for CUBICSPLINE), a rotation key of zero length, counts past
  // gltf_limits.h, a channel on a node with a matrix (glTF forbids it), two channels on one
  // node's one property, two animations of the name asked for. Channels of path "weights" (morph
  // targets) are ignored.
  static GltfAnimation load(const std::filesystem::path& path, std::string_view animation = "");

  const std::string& name() const;  // the animation's, "" when it has none
  // The largest input time of its samplers, seconds (0: nothing moves).
  double duration_s() const;
  // The node of that name in the scene load_gltf_mesh walks; nullopt when there is none. Throws
  // AssetError when two nodes carry the name (glTF does not make names unique).
  std::optional<int> find_node(std::string_view name) const;
  // Whether this animation moves the node or one of its ancestors (a translation, rotation or
  // scale channel on it). AssetError for a node index not in the scene.
  bool moves(int node) const;
  // The node's global transform at time t (seconds; before the first key and after the last the
  // end keys hold, as glTF says), in the z-up frame: N = C G(t) C^-1, where G is glTF's product of
  // the node's and its ancestors' local transforms and C turns glTF's y-up axes into z-up
  // (gltf_loader.h). A mesh loaded in the node's own frame (GltfMeshSelection::node) placed at N
  // lands where load_gltf_mesh puts the whole scene's copy of it. Throws AssetError naming the node
  // when its global transform is not a rotation, a translation and a uniform scale (a shear or a
  // non-uniform scale on it or an ancestor, at rest or in a key; a mirror): each entry of L^T L / s^2
  // (L its linear part, s^2 the mean of L^T L's diagonal) within 1e-6 of the identity's. A zero
  // scale gives scale 0 and the identity rotation. AssetError too for a node index not in the
  // scene; std::invalid_argument for a time that is not a number (+-infinity: the end keys).
  ScaledPose node_pose_at(int node, double t_s) const;
  // The file's lights (as load_gltf_lights: the same records, in the same order) with their nodes
  // posed at time t.
  std::vector<GltfLight> lights_at(double t_s) const;

  GltfAnimation(GltfAnimation&&) noexcept;
  GltfAnimation& operator=(GltfAnimation&&) noexcept;
  ~GltfAnimation();

 private:
  struct Impl;
  explicit GltfAnimation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Which nodes load_gltf_mesh takes from a file.
struct GltfMeshSelection {
  // "": the whole scene, in the scene's frame. Else the node of this name and its subtree, in the
  // node's own frame (its global transform left out: GltfAnimation::node_pose_at places it).
  // AssetError when no node or two nodes carry the name.
  std::string node;
  // Leave out every node that one of the file's animations moves, with its subtree: the static rest
  // of an animated scene (each moving part is then a proxy of its own, with `node`).
  bool skip_animated = false;
};
Mesh load_gltf_mesh(const std::filesystem::path& path, const GltfMeshSelection& selection);

}  // namespace arpipe
