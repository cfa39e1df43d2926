// A Mesh as a binary glTF 2.0 file (.glb) in memory: what `arpipe proxy simplify` writes, and what
// load_gltf_mesh (gltf_loader.h) reads back to the same triangles, positions and colours.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

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

}  // namespace arpipe
