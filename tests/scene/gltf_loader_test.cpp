// Tests of the glTF loader on small glTF 2.0 files written here (buffers embedded as base64 data
// URIs): vertex count, bounds after node transform and axis turn, colours, and every error case
// naming the file.
#include "core/scene/gltf_loader.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/scene/gltf_test_files.h"
#include "core/scene/asset_error.h"

namespace arpipe {
namespace {

using render_test::TriangleOptions;
using render_test::triangle_gltf;

class GltfLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / "gltf_loader";
    std::filesystem::create_directories(dir_);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // Loads and returns the AssetError message (fails the test when nothing is thrown).
  std::string load_error(const std::filesystem::path& path) {
    try {
      load_gltf_mesh(path);
    } catch (const AssetError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no AssetError for " << path;
    return {};
  }
  std::filesystem::path dir_;
};

TEST_F(GltfLoaderTest, TriangleLoadsWithNodeTransformAxisTurnAndColour) {
  const Mesh mesh = load_gltf_mesh(write("triangle.gltf", triangle_gltf()));
  ASSERT_EQ(mesh.vertex_count(), 3u);
  ASSERT_EQ(mesh.indices.size(), 3u);
  ASSERT_EQ(mesh.parts.size(), 1u);
  // glTF (x, y, z) after scale 0.5 and translation (0, 0, 2): (0,0,2), (.5,0,2), (0,.5,2); turned
  // into the z-up object frame (x, -z, y): (0,-2,0), (.5,-2,0), (0,-2,.5). Exact in float.
  const Bounds box = mesh.bounds();
  EXPECT_EQ(box.min[0], 0.0);
  EXPECT_EQ(box.max[0], 0.5);
  EXPECT_EQ(box.min[1], -2.0);
  EXPECT_EQ(box.max[1], -2.0);
  EXPECT_EQ(box.min[2], 0.0);
  EXPECT_EQ(box.max[2], 0.5);
  // The glTF normal +z (the model's front) becomes -y.
  for (size_t v = 0; v < 3; ++v) {
    EXPECT_NEAR(mesh.normals[3 * v], 0.0, 1e-7);
    EXPECT_NEAR(mesh.normals[3 * v + 1], -1.0, 1e-7);
    EXPECT_NEAR(mesh.normals[3 * v + 2], 0.0, 1e-7);
  }
  EXPECT_FLOAT_EQ(mesh.parts[0].base_color[0], 0.2f);
  EXPECT_FLOAT_EQ(mesh.parts[0].base_color[1], 0.4f);
  EXPECT_FLOAT_EQ(mesh.parts[0].base_color[2], 0.6f);
  EXPECT_FLOAT_EQ(mesh.parts[0].base_color[3], 1.0f);
}

TEST_F(GltfLoaderTest, MissingNormalsBecomeFlatNormalsAgreeingWithTheWinding) {
  TriangleOptions options;
  options.with_normals = false;
  options.node_transform = R"("rotation": [0, 0, 0, 1])";
  const Mesh mesh = load_gltf_mesh(write("no_normals.gltf", triangle_gltf(options)));
  ASSERT_EQ(mesh.vertex_count(), 3u);
  // Counter-clockwise in glTF's xy plane: normal +z in glTF, -y in the object frame.
  EXPECT_NEAR(mesh.normals[1], -1.0, 1e-7);
}

TEST_F(GltfLoaderTest, NodeMatrixIsApplied) {
  TriangleOptions options;
  // Column-major: translation (1, 2, 3) in the last column.
  options.node_transform = R"("matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 1,2,3,1])";
  const Bounds box = load_gltf_mesh(write("matrix.gltf", triangle_gltf(options))).bounds();
  // glTF x in [1, 2], y in [2, 3], z = 3 -> object frame x in [1, 2], y = -3, z in [2, 3].
  EXPECT_EQ(box.min[0], 1.0);
  EXPECT_EQ(box.max[0], 2.0);
  EXPECT_EQ(box.min[1], -3.0);
  EXPECT_EQ(box.max[1], -3.0);
  EXPECT_EQ(box.min[2], 2.0);
  EXPECT_EQ(box.max[2], 3.0);
}

TEST_F(GltfLoaderTest, MissingFileNamesTheFile) {
  const std::filesystem::path path = dir_ / "does_not_exist.gltf";
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
}

TEST_F(GltfLoaderTest, CorruptJsonNamesTheFileAndTheProblem) {
  const std::filesystem::path path = write("corrupt.gltf", R"({"asset": {"version": "2.0"}, "meshes": [ {)");
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a valid glTF"), std::string::npos) << message;
}

TEST_F(GltfLoaderTest, BinaryGarbageWithGlbMagicNamesTheFile) {
  const std::filesystem::path path = write("truncated.glb", std::string("glTF\x02\x00\x00\x00\x10", 9));
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("binary"), std::string::npos) << message;
}

TEST_F(GltfLoaderTest, AccessorPastTheEndOfItsBufferViewNamesThePrimitive) {
  TriangleOptions options;
  options.position_count = 300;
  const std::filesystem::path path = write("long_accessor.gltf", triangle_gltf(options));
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("mesh 0 primitive 0 POSITION: accessor 0"), std::string::npos) << message;
}

TEST_F(GltfLoaderTest, IndexPastTheLastVertexIsAnError) {
  TriangleOptions options;
  options.position_count = 2;  // indices go up to 2, so vertex 2 is missing
  options.with_normals = false;
  const std::filesystem::path path = write("bad_index.gltf", triangle_gltf(options));
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("mesh 0 primitive 0"), std::string::npos) << message;
  EXPECT_NE(message.find("past the last vertex"), std::string::npos) << message;
}

TEST_F(GltfLoaderTest, FileWithoutTrianglesIsAnError) {
  TriangleOptions options;
  options.mode = 0;  // POINTS
  const std::filesystem::path path = write("points.gltf", triangle_gltf(options));
  const std::string message = load_error(path);
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("no triangles"), std::string::npos) << message;
}

}  // namespace
}  // namespace arpipe
