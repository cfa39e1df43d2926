// The scene's exported lights (KHR_lights_punctual): placed by their nodes in the z-up frame as the
// meshes are, against hand-worked transforms; hostile light definitions refused naming the light or
// node; a mesh file with lights still loads its mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_loader.h"
#include "tests/scene/gltf_test_files.h"

namespace arpipe {
namespace {

class GltfLightsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(ARPIPE_BINARY_DIR) / "test_tmp" / "gltf_lights";
    std::filesystem::create_directories(dir_);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  std::string error_of(const std::string& text) {
    try {
      load_gltf_lights(write("bad.gltf", text));
    } catch (const AssetError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no AssetError for " << text;
    return {};
  }
  std::filesystem::path dir_;
};

// A sun turned -90 degrees about x (glTF's -z, its shining direction, becomes glTF -y: down) and a
// lamp at (0, 1, 0) under a parent at (1, 2, 3).
std::string two_lights(const std::string& lights = R"([{"type": "directional", "name": "sun", "color": [1.0, 0.9, 0.8], "intensity": 3.0},
                                                      {"type": "point", "name": "lamp", "intensity": 20.0}])",
                       int sun_light = 0) {
  return R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
             "extensions": {"KHR_lights_punctual": {"lights": )" +
         lights + R"(}},
             "scene": 0, "scenes": [{"nodes": [0, 1]}],
             "nodes": [{"name": "sun", "rotation": [-0.7071067811865476, 0.0, 0.0, 0.7071067811865476],
                        "extensions": {"KHR_lights_punctual": {"light": )" +
         std::to_string(sun_light) + R"(}}},
                       {"name": "stand", "translation": [1.0, 2.0, 3.0], "children": [2]},
                       {"name": "bulb", "translation": [0.0, 1.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 1}}}]})";
}

TEST_F(GltfLightsTest, LightsArePlacedByTheirNodesInTheZUpFrame) {
  const std::vector<GltfLight> lights = load_gltf_lights(write("lights.gltf", two_lights()));
  ASSERT_EQ(lights.size(), 2u);
  const GltfLight& sun = lights[0];
  EXPECT_EQ(sun.type, "directional");
  EXPECT_EQ(sun.name, "sun");
  EXPECT_EQ(sun.node, 0);
  EXPECT_EQ(sun.intensity, 3.0);
  EXPECT_EQ(sun.color, (Vec3{1.0, 0.9, 0.8}));
  // glTF down (-y) is arpipe's -z: (x, y, z) -> (x, -z, y).
  EXPECT_NEAR(sun.direction[0], 0, 1e-12);
  EXPECT_NEAR(sun.direction[1], 0, 1e-12);
  EXPECT_NEAR(sun.direction[2], -1, 1e-12);
  const GltfLight& bulb = lights[1];
  EXPECT_EQ(bulb.type, "point");
  EXPECT_EQ(bulb.node, 2);
  EXPECT_EQ(bulb.color, (Vec3{1, 1, 1}));  // glTF's default
  // glTF (1, 3, 3) -> (1, -3, 3).
  EXPECT_NEAR(bulb.position[0], 1, 1e-12);
  EXPECT_NEAR(bulb.position[1], -3, 1e-12);
  EXPECT_NEAR(bulb.position[2], 3, 1e-12);
}

TEST_F(GltfLightsTest, AFileWithoutLightsHasNoneAndAMeshFileWithLightsKeepsItsMesh) {
  EXPECT_TRUE(load_gltf_lights(write("triangle.gltf", render_test::triangle_gltf())).empty());
  // The triangle file with a light on its node: the mesh loads as before, the light comes out.
  std::string text = render_test::triangle_gltf();
  const size_t node = text.find("\"nodes\": [{\"mesh\"");  // the nodes array, not the scene's list
  ASSERT_NE(node, std::string::npos);
  text.insert(node + std::string("\"nodes\": [{").size(), R"("extensions": {"KHR_lights_punctual": {"light": 0}}, )");
  text.insert(node, R"("extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "spot": {"outerConeAngle": 0.5}}]}}, )");
  const std::filesystem::path file = write("triangle-lit.gltf", text);
  EXPECT_EQ(load_gltf_mesh(file).vertex_count(), 3u);
  const std::vector<GltfLight> lights = load_gltf_lights(file);
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_EQ(lights[0].type, "spot");
}

TEST_F(GltfLightsTest, BadLightsAreRefusedNamingTheLightOrNode) {
  EXPECT_NE(error_of(two_lights(R"([{"type": "area"}, {"type": "point"}])")).find("light 0: \"type\" must be"), std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([{"type": "point", "intensity": -1}, {"type": "point"}])")).find("light 0: \"intensity\" must be a number >= 0"),
            std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([{"type": "point", "color": [1, 1]}, {"type": "point"}])")).find("light 0: \"color\" must be 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([{"type": "point", "range": 0}, {"type": "point"}])")).find("\"range\" must be a number > 0"),
            std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([7, {"type": "point"}])")).find("light 0: not an object"), std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([{"type": "point"}, {"type": "point"}])", 5)).find("node 0: its KHR_lights_punctual light 5 does not exist"),
            std::string::npos);
  EXPECT_NE(error_of(two_lights(R"([{"type": "point"}, {"type": "point"}])", -1)).find("does not exist"), std::string::npos);
  std::string many = "[";
  for (int i = 0; i < 1025; ++i) many += std::string(i ? "," : "") + R"({"type": "point"})";
  EXPECT_NE(error_of(two_lights(many + "]")).find("1025 lights, over the limit of 1024"), std::string::npos);
}

}  // namespace
}  // namespace arpipe
