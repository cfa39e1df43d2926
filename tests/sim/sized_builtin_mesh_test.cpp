// Sized builtin meshes in simulator scenes ([[object]] size_m with "builtin:box",
// "builtin:cylinder", "builtin:plane"): the loader reads and checks size_m (every bad value names
// the file, line and object), the simulator builds the mesh at that size (an elliptic cylinder
// seen from above covers its ellipse's area) and it casts shadows like any other object (a
// virtual box's hard shadow where the light's rays through the box meet the table).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>

#include "capture/sim/ground_truth_coverage.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/shadow_factor.h"
#include "capture/sim/sim_scene_loader.h"
#include "capture/sim/simulator.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

using namespace arpipe::sim::test;

constexpr double kPi = std::numbers::pi;

SimScene parse(const std::string& text, const fs::path& base = {}) { return parse_sim_scene(text, "scene.toml", base); }

// The message names the file and line ("scene.toml:<line>:<col>: "), the dotted key and `also`.
void expect_error(const std::string& text, int line, const std::string& key, const std::string& also,
                  const fs::path& base = {}) {
  SCOPED_TRACE(text);
  try {
    parse(text, base);
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("scene.toml:" + std::to_string(line) + ":", 0), 0u) << message;
    EXPECT_NE(message.find(" " + key + ": "), std::string::npos) << "key " << key << " not in: " << message;
    EXPECT_NE(message.find(also), std::string::npos) << "'" << also << "' not in: " << message;
  }
}

std::string mesh_object(const std::string& mesh, const std::string& size) {
  return "[[object]]\nname = \"a\"\n[[object]]\nname = \"b\"\nshape = \"mesh\"\nmesh = \"" + mesh + "\"\nsize_m = " +
         size + "\n";  // size_m on line 7, object[1]
}

TEST(SizedBuiltinMeshes, TheLoaderReadsSizeM) {
  const SimScene scene = parse(mesh_object("builtin:box", "[0.12, 0.08, 0.1]") +
                               "[[object]]\nshape = \"mesh\"\nmesh = \"builtin:cylinder\"\nsize_m = [0.07, 0.05, 0.12]\n"
                               "[[object]]\nshape = \"mesh\"\nmesh = \"builtin:plane\"\nsize_m = [0.5, 0.25, 0]\n"
                               "[[object]]\nshape = \"mesh\"\nmesh = \"builtin:box\"\n");
  ASSERT_EQ(scene.objects.size(), 5u);
  EXPECT_FALSE(scene.objects[0].mesh_size_m);  // a plane
  ASSERT_TRUE(scene.objects[1].mesh_size_m);
  EXPECT_EQ(*scene.objects[1].mesh_size_m, (Vec3{0.12, 0.08, 0.1}));
  EXPECT_EQ(scene.objects[1].mesh_builtin, "builtin:box");
  ASSERT_TRUE(scene.objects[2].mesh_size_m);
  EXPECT_EQ(*scene.objects[2].mesh_size_m, (Vec3{0.07, 0.05, 0.12}));
  ASSERT_TRUE(scene.objects[3].mesh_size_m);  // a plane's z is ignored, so 0 will do
  EXPECT_EQ(*scene.objects[3].mesh_size_m, (Vec3{0.5, 0.25, 0}));
  EXPECT_FALSE(scene.objects[4].mesh_size_m);  // the builtin's own size
}

TEST(SizedBuiltinMeshes, BadSizesNameTheFileLineAndObject) {
  const std::string key = "object[1].size_m";
  // Each bad number is named by its index in the array.
  expect_error(mesh_object("builtin:box", "[0.12, 0, 0.1]"), 7, key + "[1]", "(0, 1000]");
  expect_error(mesh_object("builtin:box", "[0.12, 0.08, -0.1]"), 7, key + "[2]", "(0, 1000]");
  expect_error(mesh_object("builtin:cylinder", "[0.07, 0.07, 0]"), 7, key + "[2]", "(0, 1000]");
  expect_error(mesh_object("builtin:box", "[0.12, 0.08, inf]"), 7, key + "[2]", "finite");
  expect_error(mesh_object("builtin:box", "[nan, 0.08, 0.1]"), 7, key + "[0]", "finite");
  expect_error(mesh_object("builtin:box", "[2000, 0.08, 0.1]"), 7, key + "[0]", "2000");
  expect_error(mesh_object("builtin:box", "[0.12, 0.08]"), 7, key, "2 items");
  expect_error(mesh_object("builtin:box", "0.1"), 7, key, "");
  expect_error(mesh_object("builtin:box", "\"big\""), 7, key, "a string");
  expect_error(mesh_object("builtin:plane", "[0, 0.5, 0]"), 7, key, "a zero side");
  expect_error(mesh_object("builtin:plane", "[0.5, 0.5, -1]"), 7, key + "[2]", "[0, 1000]");
  // Where a size means nothing: fixed-size builtins, glTF files, other shapes.
  expect_error(mesh_object("builtin:cube", "[0.1, 0.1, 0.1]"), 7, key, "mesh_scale");
  expect_error("[[object]]\nshape = \"sphere\"\nsize_m = [0.1, 0.1, 0.1]\n", 3, "object[0].size_m", "mesh");
  expect_error("[[object]]\nsize_m = [0.1, 0.1, 0.1]\n", 2, "object[0].size_m", "mesh");

  const fs::path dir = scratch_dir("sized-gltf");
  fs::create_directories(dir);
  // One triangle in the xy plane, its buffer embedded as a data URI.
  std::ofstream(dir / "tri.gltf")
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})";
  EXPECT_NO_THROW(parse("[[object]]\nshape = \"mesh\"\nmesh = \"tri.gltf\"\n", dir));
  expect_error(mesh_object("tri.gltf", "[0.1, 0.1, 0.1]"), 7, key, "glTF", dir);
}

TEST(SizedBuiltinMeshes, TheSimulatorRefusesBadSizesGivenInCode) {
  SimScene scene;
  SimObject box;
  box.name = "carton";
  box.shape = SimObject::Shape::Mesh;
  box.mesh_builtin = "builtin:box";
  box.mesh_size_m = Vec3{0.1, 0.0, 0.1};
  scene.objects.push_back(box);
  try {
    SceneShader shader(scene, true);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("carton"), std::string::npos) << e.what();
  }
  scene.objects[0].mesh_size_m = Vec3{0.1, 0.1, std::nan("")};
  EXPECT_THROW(SceneShader(scene, true), std::invalid_argument);
  scene.objects[0].mesh_builtin = "builtin:cube";
  scene.objects[0].mesh_size_m = Vec3{0.1, 0.1, 0.1};
  EXPECT_THROW(SceneShader(scene, true), std::invalid_argument);
  scene.objects[0].mesh_builtin = "builtin:plane";
  scene.objects[0].mesh_size_m = Vec3{0.1, 0.1, 0.0};
  EXPECT_NO_THROW(SceneShader(scene, true));
}

// Straight down onto an upright cylinder with an elliptic section: the side walls hide under the
// nearer top cap, so the virtual object covers the cap's outline, a 48-gon inscribed in the
// ellipse of semi-axes f a / d and f b / d (d: camera to the cap), area (48/2) sin(2 pi/48) x
// those. Summed coverage against it says the size was used along each axis.
TEST(SizedBuiltinMeshes, AnEllipticCylinderSeenFromAboveCoversItsEllipse) {
  const int width = 120, height = 90;
  const double f = 300, a = 0.05, b = 0.025, h = 0.04, camera_z = 0.54;
  SimScene scene;
  scene.camera = exact_camera(width, height, f);
  scene.trajectory = still({0, 0, camera_z}, {0, 0, 0}, {0, 1, 0});
  scene.render.samples_per_pixel = 16;
  scene.objects.push_back(ground_plane("table", 2, 2));
  scene.objects.back().T_world_object = SE3(identity3(), {0, 0, -0.0005});
  SimObject cylinder;
  cylinder.name = "tin";
  cylinder.shape = SimObject::Shape::Mesh;
  cylinder.mesh_builtin = "builtin:cylinder";
  cylinder.mesh_size_m = Vec3{2 * a, 2 * b, h};
  cylinder.is_virtual = true;
  scene.objects.push_back(cylinder);
  scene.lights.push_back(overhead_sun(3));
  const fs::path dir = scratch_dir("sized-cylinder");
  SimulateOptions options;
  options.out_dir = dir;
  options.frames = 1;
  simulate(scene, options);
  const CoverageImage coverage = read_coverage_frame(dir, 0);
  double sum = 0, sum_x = 0, sum_y = 0, extent_x = 0, extent_y = 0;
  const double cx = (width - 1) / 2.0, cy = (height - 1) / 2.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double c = coverage.at(x, y);
      sum += c;
      sum_x += c * (x - cx) * (x - cx);
      sum_y += c * (y - cy) * (y - cy);
      if (c > 0) {
        extent_x = std::max(extent_x, std::abs(x - cx) - 0.5);
        extent_y = std::max(extent_y, std::abs(y - cy) - 0.5);
      }
    }
  const double d = camera_z - h, A = f * a / d, B = f * b / d;  // 30 and 15 px
  const double polygon_area = kPi * A * B * std::sin(2 * kPi / 48) / (2 * kPi / 48);
  EXPECT_NEAR(sum, polygon_area, 0.005 * polygon_area + 2.0);
  // Second moments of an ellipse: area x A^2 / 4 along x, area x B^2 / 4 along y (the 48-gon's
  // are within 0.6 % of them); the outline's extent along each axis.
  EXPECT_NEAR(sum_x / sum, A * A / 4, 0.02 * A * A / 4);
  EXPECT_NEAR(sum_y / sum, B * B / 4, 0.02 * B * B / 4);
  EXPECT_NEAR(extent_x, A, 1.0);
  EXPECT_NEAR(extent_y, B, 1.0);
}

// A virtual 4 x 10 x 6 cm box under a hard light from +x, 45 degrees up, and no sky: a table point
// (x, y) is in its shadow exactly when |y| < 0.05 and x + s lies in [-0.02, 0.02] for some s in
// [0, 0.06 + 0.0005] (the ray climbs one metre per metre): x in [-0.0805, 0.02]. The ray-traced
// shadow factor is 0 there (seen beside the box, x < -0.02) and 1 elsewhere.
TEST(SizedBuiltinMeshes, AVirtualBoxCastsItsShadowAtItsSize) {
  const int width = 160, height = 120;
  SimScene scene;
  scene.camera = exact_camera(width, height, 150);
  const Vec3 position{-0.30, -0.15, 0.35}, look_at{-0.05, 0, 0};
  scene.trajectory = still(position, look_at, {0, 0, 1});
  scene.objects.push_back(ground_plane("table", 2, 2));
  scene.objects.back().T_world_object = SE3(identity3(), {0, 0, -0.0005});
  SimObject box;
  box.name = "box";
  box.shape = SimObject::Shape::Mesh;
  box.mesh_builtin = "builtin:box";
  box.mesh_size_m = Vec3{0.04, 0.10, 0.06};
  box.is_virtual = true;
  scene.objects.push_back(box);
  SimLight light = overhead_sun(3);
  light.direction_to_light = normalized(Vec3{1, 0, 1});
  scene.lights.push_back(light);

  // The camera's pose, independently: x right, y down, z towards look_at.
  const Vec3 z = normalized(look_at - position);
  const Vec3 y = normalized(Vec3{0, 0, -1} - dot(Vec3{0, 0, -1}, z) * z);
  const Vec3 x = cross(y, z);
  const Mat3 R{{{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}}};
  const SE3 T_cam_world(R, -1.0 * mat_mul(R, position));
  const ShadowFactorImage factor =
      render_shadow_factor(scene, scene.camera.model, T_cam_world, 1, PixelRegion{0, 0, width, height});

  // Table points 5 mm or more inside or outside the shadow's edges (a pixel is under 2 mm here).
  int shadowed = 0, lit = 0;
  for (double px = -0.20; px <= 0.0; px += 0.005)
    for (double py = -0.12; py <= 0.12; py += 0.005) {
      const bool in_shadow = px >= -0.075 && px <= -0.025 && std::abs(py) <= 0.045;
      const bool in_light = px <= -0.0855 || (std::abs(py) >= 0.055 && px <= -0.025);
      if (!in_shadow && !in_light) continue;
      const auto q = scene.camera.model.project(T_cam_world * Vec3{px, py, -0.0005});
      ASSERT_TRUE(q);
      const int u = int(std::lround((*q)[0])), v = int(std::lround((*q)[1]));
      if (u < 0 || v < 0 || u >= width || v >= height || !factor.valid_at(u, v)) continue;
      if (in_shadow) {
        EXPECT_LT(factor.at(u, v), 1e-6) << px << ", " << py;
        ++shadowed;
      } else {
        EXPECT_NEAR(factor.at(u, v), 1.0, 1e-6) << px << ", " << py;
        ++lit;
      }
    }
  EXPECT_GT(shadowed, 50);
  EXPECT_GT(lit, 200);
}

}  // namespace
}  // namespace arpipe::sim
