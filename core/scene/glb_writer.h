// A Mesh as a binary glTF 2.0 file (.glb) in memory: what `arpipe proxy simplify` writes, and what
// load_gltf_mesh (gltf_loader.h) reads back to the same triangles, positions and colours.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"
#include "core/scene/gltf_loader.h"
#include "core/scene/mesh.h"

namespace arpipe {

// One node, one mesh, one primitive per part (its own compacted vertices: POSITION with min and
// max, NORMAL when the mesh has normals, 32-bit indices) with a material holding the part's base
// colour. The object frame (z up) turns into glTF's y-up axes as the loader turns them back:
// glTF (x, y, z) = object (x, z, -y). `generator` goes into asset.generator.
// Throws std::invalid_argument for a mesh that is not one (no triangles, an index past the last
// vertex, a position or normal not finite, normals not one per vertex, a part outside the indices)
// or too large for a .glb's 32-bit lengths.
// lights: KHR_lights_punctual lights ("directional" or "point"), each on a node of its own placed
// so that load_gltf_lights reads back its position and direction (z-up, as the mesh).
std::vector<uint8_t> encode_glb(const Mesh& mesh, std::string_view generator, const std::vector<GltfLight>& lights = {});

// A moving part of a scene: a root node of its own holding `mesh` in the node's own frame (z-up),
// placed over time by LINEAR translation and rotation channels with a key at each of `keys` (the
// quaternions kept on one hemisphere, so that glTF's slerp takes the short way: the path of
// SE3::interpolate between the same keys). The node's rest transform is the first key's.
struct GlbAnimatedNode {
  std::string name;
  Mesh mesh;
  struct Key {
    double t_s = 0;     // >= 0, strictly increasing
    SE3 T_world_node;   // z-up
  };
  std::vector<Key> keys;  // at least one
};
// The same file with animated nodes: `mesh` is the static part (its one node as above; it may be
// empty when `animated` is not), each animated node a root node with its mesh, and one animation
// named `animation_name` moving them all. Throws std::invalid_argument as above, and for an
// animated node without keys, with times not finite, negative or not increasing, or with a name
// that is empty or used twice.
std::vector<uint8_t> encode_glb(const Mesh& mesh, std::string_view generator, const std::vector<GltfLight>& lights,
                                const std::vector<GlbAnimatedNode>& animated, std::string_view animation_name = "scene");

}  // namespace arpipe
