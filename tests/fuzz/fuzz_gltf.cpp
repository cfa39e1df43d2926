// libFuzzer target: core/scene's glTF 2.0 loader (load_gltf_mesh, load_gltf_lights) on a .gltf
// (JSON) or .glb file. Bad input must be an AssetError; a loaded mesh must be consistent (indices in
// range), a loaded light finite with a unit direction.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_loader.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

namespace {

void check_mesh(const arpipe::Mesh& mesh) {
  ARPIPE_FUZZ_CHECK(mesh.positions.size() % 3 == 0, "positions come in threes");
  ARPIPE_FUZZ_CHECK(mesh.normals.size() == mesh.positions.size(), "a normal per vertex");
  ARPIPE_FUZZ_CHECK(mesh.indices.size() % 3 == 0, "indices come in triangles");
  for (const uint32_t index : mesh.indices) ARPIPE_FUZZ_CHECK(index < mesh.vertex_count(), "index within the vertices");
  for (const arpipe::MeshPart& part : mesh.parts)
    ARPIPE_FUZZ_CHECK(static_cast<uint64_t>(part.first_index) + part.index_count <= mesh.indices.size(),
                      "part within the indices");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader tells JSON from binary by the magic bytes, not the name.
  const std::filesystem::path file = arpipe::fuzz::write_temp_file("model.gltf", data, size);
  try {
    check_mesh(arpipe::load_gltf_mesh(file));
  } catch (const arpipe::AssetError&) {
  }
  try {
    for (const arpipe::GltfLight& light : arpipe::load_gltf_lights(file)) {
      ARPIPE_FUZZ_CHECK(std::abs(arpipe::norm(light.direction) - 1) < 1e-9, "a unit direction");
      ARPIPE_FUZZ_CHECK(std::isfinite(light.position[0] + light.position[1] + light.position[2]), "a finite position");
      ARPIPE_FUZZ_CHECK(light.intensity >= 0 && std::isfinite(light.intensity), "a finite intensity >= 0");
    }
  } catch (const arpipe::AssetError&) {
  }
  return 0;
}
