// Loads the triangle meshes of a glTF 2.0 file (.gltf or .glb, via tinygltf) into one Mesh, with
// node transforms applied and glTF's y-up axes turned into arpipe's z-up object frame.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/geometry/vec.h"
#include "core/scene/mesh.h"

namespace arpipe {

// Walks the default scene (else the first scene, else every root node). Triangle lists, strips and
// fans are kept; points and lines are skipped. Each primitive becomes one MeshPart coloured by its
// material's baseColorFactor (white without a material). Normals missing from the file are made
// flat, as glTF asks. The axes turn so that glTF's +y (up) is the object's +z and glTF's +z (the
// model's front) is -y; units stay metres.
// The file is untrusted (gltf_document.h, gltf_limits.h): only regular files are read, external
// buffers only inside the file's own folder (symlinks resolved; images are never read), every
// offset and size is checked with overflow-checked arithmetic before a byte is read or a vector
// made, the node graph is walked iteratively and must be a strict tree (no node with two parents)
// within kMaxGltfNodeDepth, the output within kMaxGltfTriangles and kMaxGltfVertices; positions,
// normals and node transforms must be finite. A node's rotation is normalised (glTF asks for unit
// quaternions; one of zero length stays the identity). Mesh::source is set to `path`.
// load_gltf_mesh(path, GltfMeshSelection) (gltf_animation.h) takes one node's subtree or the scene
// without its animated nodes; this one is the whole scene, GltfMeshSelection{}.
// Throws AssetError (and nothing else) naming the file and what was wrong: missing or unreadable
// file, JSON or GLB syntax, a limit (stated in the message), a bad accessor (naming the mesh,
// primitive, attribute and accessor), a bad node (naming it), no triangles at all.
Mesh load_gltf_mesh(const std::filesystem::path& path);

// A KHR_lights_punctual light of the scene, placed by its node (z-up, as the meshes).
struct GltfLight {
  std::string name;
  std::string type;           // "directional", "point" or "spot"
  Vec3 color{1, 1, 1};        // linear RGB
  double intensity = 1;       // directional: lux (lm/m^2); point and spot: candela (lm/sr)
  double range = 0;           // 0: without limit
  Vec3 position{0, 0, 0};     // point and spot: where it is
  Vec3 direction{0, 0, -1};   // directional and spot: the way it shines (unit; the node's -z)
  int node = -1;
};

// The lights on the nodes of the scene that load_gltf_mesh walks (the same file checks and node
// rules; meshes are not read). Empty when the file has none. Throws AssetError naming the file.
std::vector<GltfLight> load_gltf_lights(const std::filesystem::path& path);

}  // namespace arpipe
