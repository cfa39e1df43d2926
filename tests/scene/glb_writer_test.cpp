// Tests of the .glb writer: what it writes loads back through load_gltf_mesh with the same
// triangles, positions (bit for bit), normals and colours; the container is well formed; meshes
// that are not one are refused.
#include "core/scene/glb_writer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "core/scene/builtin_meshes.h"
#include "core/scene/gltf_loader.h"
#include "core/scene/mesh_simplify.h"

namespace arpipe {
namespace {

class GlbWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / "glb_writer";
    std::filesystem::create_directories(dir_);
  }
  Mesh round_trip(const Mesh& mesh, const std::string& name) {
    const std::vector<uint8_t> bytes = encode_glb(mesh, "arpipe test");
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return load_gltf_mesh(path);
  }
  std::filesystem::path dir_;
};

// Corner k of triangle t, as a position.
std::array<float, 3> corner(const Mesh& mesh, size_t t, size_t k) {
  const size_t v = mesh.indices[3 * t + k];
  return {mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
}
std::array<float, 3> corner_normal(const Mesh& mesh, size_t t, size_t k) {
  const size_t v = mesh.indices[3 * t + k];
  return {mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]};
}

void expect_same_triangles(const Mesh& written, const Mesh& loaded) {
  ASSERT_EQ(loaded.triangle_count(), written.triangle_count());
  ASSERT_EQ(loaded.parts.size(), written.parts.size());
  for (size_t p = 0; p < written.parts.size(); ++p) {
    EXPECT_EQ(loaded.parts[p].index_count, written.parts[p].index_count);
    EXPECT_EQ(loaded.parts[p].base_color, written.parts[p].base_color);
  }
  for (size_t t = 0; t < written.triangle_count(); ++t)
    for (size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(corner(loaded, t, k), corner(written, t, k)) << "triangle " << t << " corner " << k;
      const std::array<float, 3> a = corner_normal(loaded, t, k), b = corner_normal(written, t, k);
      for (size_t axis = 0; axis < 3; ++axis) ASSERT_NEAR(a[axis], b[axis], 1e-6);
    }
}

TEST_F(GlbWriterTest, SimplifiedSphereLoadsBackWithTheSameTrianglesAndPositions) {
  const MeshSimplifyResult result = simplify_mesh(make_sphere_mesh(0.03, 80), MeshSimplifySettings{});
  expect_same_triangles(result.mesh, round_trip(result.mesh, "sphere.glb"));
  MeshSimplifySettings smooth;
  smooth.normals = ProxyNormals::smooth;
  const MeshSimplifyResult shared = simplify_mesh(make_sphere_mesh(0.03, 40), smooth);
  const Mesh loaded = round_trip(shared.mesh, "smooth.glb");
  expect_same_triangles(shared.mesh, loaded);
  EXPECT_EQ(loaded.vertex_count(), shared.mesh.vertex_count());  // shared vertices stay shared
}

TEST_F(GlbWriterTest, PartsKeepTheirColoursAndAMeshWithoutNormalsGetsFlatOnes) {
  Mesh box = make_box_mesh({0.1, 0.2, 0.3}, 2);
  const uint32_t half = static_cast<uint32_t>(box.indices.size() / 6 * 3);  // whole triangles
  box.parts = {MeshPart{0, half, {1, 0, 0, 1}}, MeshPart{half, static_cast<uint32_t>(box.indices.size()) - half, {0, 0.5f, 1, 0.25f}}};
  expect_same_triangles(box, round_trip(box, "box.glb"));

  box.normals.clear();
  const Mesh loaded = round_trip(box, "no_normals.glb");
  ASSERT_EQ(loaded.triangle_count(), box.triangle_count());
  for (size_t t = 0; t < box.triangle_count(); ++t)
    for (size_t k = 0; k < 3; ++k) ASSERT_EQ(corner(loaded, t, k), corner(box, t, k));
}

TEST_F(GlbWriterTest, ContainerIsAlignedAndItsLengthsAddUp) {
  Mesh cube = make_cube_mesh(0.06, 1);
  cube.source = "builtin:cube";
  const std::vector<uint8_t> glb = encode_glb(cube, "arpipe test");
  auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  ASSERT_GE(glb.size(), 28u);
  EXPECT_EQ(std::memcmp(glb.data(), "glTF", 4), 0);
  EXPECT_EQ(u32(4), 2u);
  EXPECT_EQ(u32(8), glb.size());
  const uint32_t json_length = u32(12);
  EXPECT_EQ(json_length % 4, 0u);
  EXPECT_EQ(std::memcmp(glb.data() + 16, "JSON", 4), 0);
  const std::string json(reinterpret_cast<const char*>(glb.data() + 20), json_length);
  EXPECT_NE(json.find("\"generator\":\"arpipe test\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"name\":\"builtin:cube\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"min\""), std::string::npos) << json;  // POSITION's bounds, as the spec asks
  const uint32_t bin_length = u32(20 + json_length);
  EXPECT_EQ(std::memcmp(glb.data() + 24 + json_length, "BIN\0", 4), 0);
  EXPECT_EQ(bin_length % 4, 0u);
  EXPECT_EQ(28u + json_length + bin_length, glb.size());
}

TEST_F(GlbWriterTest, MeshesThatAreNotOneAreRefused) {
  const Mesh cube = make_cube_mesh(0.06, 1);
  Mesh empty;
  EXPECT_THROW(encode_glb(empty, "t"), std::invalid_argument);
  Mesh nan = cube;
  nan.positions[4] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(encode_glb(nan, "t"), std::invalid_argument);
  Mesh past = cube;
  past.indices[0] = 9999;
  EXPECT_THROW(encode_glb(past, "t"), std::invalid_argument);
  Mesh normals = cube;
  normals.normals.pop_back();
  EXPECT_THROW(encode_glb(normals, "t"), std::invalid_argument);
  Mesh part = cube;
  part.parts[0].index_count += 3;
  EXPECT_THROW(encode_glb(part, "t"), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe
