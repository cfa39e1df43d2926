// The simulator scene's export read back by arpipe's own glTF loaders: the real objects' triangles
// where the ray tracer has them (world frame, z up), a part per object with its albedo, the
// virtual ones left out, and the lights' directions and positions as the scene gives them.
#include "capture/sim/scene_export.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "capture/sim/sim_scene_loader.h"
#include "core/scene/gltf_loader.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe {
namespace {

constexpr const char* kScene = R"(
[[object]]
name = "table"
position = [0.0, 0.0, -0.01]
width_m = 2.0
height_m = 1.0
albedo = [0.35, 0.30, 0.25]

[[object]]
name = "ball"
shape = "sphere"
radius_m = 0.1
position = [0.5, 0.2, 0.1]
albedo = [0.8, 0.1, 0.1]

[[object]]
name = "box"
shape = "mesh"
mesh = "builtin:box"
size_m = [0.2, 0.1, 0.3]
position = [-0.5, 0.0, 0.0]
rotation_deg = [0.0, 0.0, 90.0]

[[object]]
name = "virtual-cube"
shape = "mesh"
mesh = "builtin:cube"
virtual = true

[sun]
azimuth_deg = 135.0
elevation_deg = 40.0
irradiance = 800.0

[[light]]
name = "lamp"
kind = "point"
position = [0.3, -0.4, 1.2]
intensity = 25.0
)";

TEST(SceneExport, TheRealWorldAndItsLightsReadBackWhereTheSceneHasThem) {
  const sim::SimScene scene = sim::parse_sim_scene(kScene, "export.toml", ARPIPE_SOURCE_DIR);
  const std::filesystem::path dir = sim::test::scratch_dir("scene-export");
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "world.glb";
  const std::vector<uint8_t> glb = sim::export_scene_glb(scene);
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));

  const Mesh mesh = load_gltf_mesh(file);
  ASSERT_EQ(mesh.parts.size(), 3u);  // the virtual cube left out
  const Bounds bounds = mesh.bounds();
  // The table spans x in [-1, 1], y in [-0.5, 0.5] at z = -0.01; the ball reaches z = 0.2; the box
  // turned 90 degrees spans x in [-0.55, -0.45] and y in [-0.1, 0.1], up to z = 0.3.
  EXPECT_NEAR(bounds.min[0], -1.0, 1e-6);
  EXPECT_NEAR(bounds.max[0], 1.0, 1e-6);
  EXPECT_NEAR(bounds.min[1], -0.5, 1e-6);
  EXPECT_NEAR(bounds.max[1], 0.5, 1e-6);
  EXPECT_NEAR(bounds.min[2], -0.01, 1e-6);
  EXPECT_NEAR(bounds.max[2], 0.3, 1e-6);
  // Each part's own extent and colour.
  const auto part_bounds = [&](size_t k) {
    Bounds b{{1e9, 1e9, 1e9}, {-1e9, -1e9, -1e9}};
    const MeshPart& part = mesh.parts[k];
    for (uint32_t i = part.first_index; i < part.first_index + part.index_count; ++i)
      for (int c = 0; c < 3; ++c) {
        b.min[size_t(c)] = std::min(b.min[size_t(c)], double(mesh.positions[3 * size_t(mesh.indices[i]) + size_t(c)]));
        b.max[size_t(c)] = std::max(b.max[size_t(c)], double(mesh.positions[3 * size_t(mesh.indices[i]) + size_t(c)]));
      }
    return b;
  };
  const Bounds ball = part_bounds(1);
  EXPECT_NEAR(ball.max[2], 0.2, 1e-6);
  EXPECT_NEAR(ball.min[2], 0.0, 1e-6);
  EXPECT_NEAR(0.5 * (ball.min[0] + ball.max[0]), 0.5, 1e-6);
  EXPECT_FLOAT_EQ(mesh.parts[1].base_color[0], 0.8f);
  const Bounds box = part_bounds(2);
  EXPECT_NEAR(box.min[0], -0.55, 1e-6);
  EXPECT_NEAR(box.max[0], -0.45, 1e-6);
  EXPECT_NEAR(box.min[1], -0.1, 1e-6);
  EXPECT_NEAR(box.max[1], 0.1, 1e-6);

  const std::vector<GltfLight> lights = load_gltf_lights(file);
  ASSERT_EQ(lights.size(), scene.lights.size());
  for (size_t k = 0; k < lights.size(); ++k) {
    const sim::SimLight& expected = scene.lights[k];
    if (expected.kind == sim::SimLight::Kind::Directional) {
      EXPECT_EQ(lights[k].type, "directional");
      EXPECT_NEAR(lights[k].intensity, expected.irradiance, 1e-9);
      for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(lights[k].direction[c], -expected.direction_to_light[c], 1e-9) << c;
    } else {
      EXPECT_EQ(lights[k].type, "point");
      EXPECT_EQ(lights[k].name, "lamp");
      EXPECT_NEAR(lights[k].intensity, 25.0, 1e-12);
      for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(lights[k].position[c], expected.position[c], 1e-9) << c;
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(SceneExport, ASceneWithNothingRealIsRefused) {
  const sim::SimScene scene = sim::parse_sim_scene("[[object]]\nshape = \"sphere\"\nvirtual = true\n", "empty.toml", ARPIPE_SOURCE_DIR);
  EXPECT_THROW(sim::export_scene_glb(scene), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe
