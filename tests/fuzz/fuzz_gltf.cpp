// libFuzzer target: core/scene's glTF 2.0 loader (load_gltf_mesh, its node selection,
// load_gltf_lights) and its node animations (GltfAnimation: load, node_pose_at, lights_at) on a
// .gltf (JSON) or .glb file. Bad input must be an AssetError; a loaded mesh must be consistent
// (indices in range), a light finite with a unit direction, a node's pose finite with a rotation and
// a scale >= 0.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_animation.h"
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

void check_lights(const std::vector<arpipe::GltfLight>& lights) {
  for (const arpipe::GltfLight& light : lights) {
    ARPIPE_FUZZ_CHECK(std::abs(arpipe::norm(light.direction) - 1) < 1e-9, "a unit direction");
    ARPIPE_FUZZ_CHECK(std::isfinite(light.position[0] + light.position[1] + light.position[2]), "a finite position");
    ARPIPE_FUZZ_CHECK(light.intensity >= 0 && std::isfinite(light.intensity), "a finite intensity >= 0");
  }
}

void check_pose(const arpipe::ScaledPose& placed) {
  ARPIPE_FUZZ_CHECK(std::isfinite(placed.scale) && placed.scale >= 0, "a finite scale >= 0");
  const arpipe::Vec3& t = placed.pose.translation();
  ARPIPE_FUZZ_CHECK(std::isfinite(t[0] + t[1] + t[2]), "a finite translation");
  const arpipe::Mat3& R = placed.pose.rotation();
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      const double dot = R[0][i] * R[0][j] + R[1][i] * R[1][j] + R[2][i] * R[2][j];
      ARPIPE_FUZZ_CHECK(std::abs(dot - (i == j ? 1.0 : 0.0)) < 1e-6, "an orthonormal rotation");
    }
}

// The first animation (or the rest pose) at a few times: the first nodes' poses and the lights.
void check_animation(const std::filesystem::path& file) {
  const arpipe::GltfAnimation animation = arpipe::GltfAnimation::load(file);
  const double end = animation.duration_s();
  ARPIPE_FUZZ_CHECK(std::isfinite(end) && end >= 0, "a finite duration >= 0");
  for (const double t : {-1.0, 0.0, 0.37 * end, end, end + 1}) {
    for (int node = 0; node < 8; ++node) {
      try {
        check_pose(animation.node_pose_at(node, t));
        animation.moves(node);
      } catch (const arpipe::AssetError&) {  // not a node of the scene, or not rigid
      }
    }
    try {
      check_lights(animation.lights_at(t));
    } catch (const arpipe::AssetError&) {  // a light under a zero scale at t
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader tells JSON from binary by the magic bytes, not the name.
  const std::filesystem::path file = arpipe::fuzz::write_temp_file("model.gltf", data, size);
  try {
    check_mesh(arpipe::load_gltf_mesh(file));
  } catch (const arpipe::AssetError&) {
  }
  // The static rest, and one node's subtree (the animated seeds' moving node is "arm").
  for (const arpipe::GltfMeshSelection& selection : {arpipe::GltfMeshSelection{"", true}, arpipe::GltfMeshSelection{"arm", false}}) {
    try {
      check_mesh(arpipe::load_gltf_mesh(file, selection));
    } catch (const arpipe::AssetError&) {
    }
  }
  try {
    check_lights(arpipe::load_gltf_lights(file));
  } catch (const arpipe::AssetError&) {
  }
  try {
    check_animation(file);
  } catch (const arpipe::AssetError&) {
  }
  return 0;
}
