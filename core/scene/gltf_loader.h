// Loads the triangle meshes of a glTF 2.0 file (.gltf or .glb, via tinygltf) into one Mesh, with
// node transforms applied and glTF's y-up axes turned into arpipe's z-up object frame.
#pragma once

#include <filesystem>

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
// normals and node transforms must be finite. Mesh::source is set to `path`.
// Throws AssetError (and nothing else) naming the file and what was wrong: missing or unreadable
// file, JSON or GLB syntax, a limit (stated in the message), a bad accessor (naming the mesh,
// primitive, attribute and accessor), a bad node (naming it), no triangles at all.
Mesh load_gltf_mesh(const std::filesystem::path& path);

}  // namespace arpipe
