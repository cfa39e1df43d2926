// A simulator scene with moving objects exported as the hybrid viewer reads it
// (export_scene_glb): each real object with keys an animated node of its own that a glTF reader
// (GltfAnimation) places where object_pose_at does, at the keys and between them, within 1e-6 m
// and 1e-6 rad; the rest the static mesh, without it; a virtual one left out.
#include "capture/sim/scene_export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "capture/sim/sim_scene_loader.h"
#include "core/scene/gltf_animation.h"
#include "tests/sim/sim_test_support.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kDeg = std::numbers::pi / 180.0;

SimScene hybrid_scene() { return load_sim_scene(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "hybrid-animated.toml"); }

const SimObject& object_named(const SimScene& scene, const std::string& name) {
  for (const auto& object : scene.objects)
    if (object.name == name) return object;
  throw std::runtime_error("no object " + name);
}

fs::path exported(const SimScene& scene, const std::string& name) {
  const fs::path dir = test::scratch_dir(name);
  fs::create_directories(dir);
  const std::vector<uint8_t> glb = export_scene_glb(scene);
  std::ofstream(dir / "scene.glb", std::ios::binary).write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));
  return dir / "scene.glb";
}

// The triangles of a mesh whose part has the given colour.
size_t triangles_of_colour(const Mesh& mesh, const Rgb& albedo) {
  size_t count = 0;
  for (const MeshPart& part : mesh.parts)
    if (std::abs(part.base_color[0] - float(albedo[0])) < 1e-6f && std::abs(part.base_color[1] - float(albedo[1])) < 1e-6f &&
        std::abs(part.base_color[2] - float(albedo[2])) < 1e-6f)
      count += part.index_count / 3;
  return count;
}

TEST(AnimatedSceneExport, TheHybridScenesCartMovesAsTheSimulatedOne) {
  const SimScene scene = hybrid_scene();
  const SimObject& cart = object_named(scene, "cart");
  const fs::path file = exported(scene, "hybrid-export");
  const GltfAnimation animation = GltfAnimation::load(file);
  EXPECT_EQ(animation.name(), std::string(kSceneAnimationName));
  EXPECT_NEAR(animation.duration_s(), 2.0, 1e-6);
  const std::optional<int> node = animation.find_node("cart");
  ASSERT_TRUE(node.has_value());
  EXPECT_TRUE(animation.moves(*node));
  EXPECT_FALSE(animation.find_node("virtual-cube").has_value());
  // At each key, between keys (every frame's time and a few more), and outside them.
  std::vector<double> times{-0.5, 2.0, 2.5};
  for (const SimPoseKey& key : cart.keyframes) times.push_back(key.time_s);
  for (int k = 0; k < 60; ++k) times.push_back(k / 30.0);
  for (double t : {0.123, 0.8 + 1e-4, 1.3999, 1.77}) times.push_back(t);
  for (double t : times) {
    SCOPED_TRACE(t);
    const ScaledPose placed = animation.node_pose_at(*node, t);
    const SE3 truth = object_pose_at(cart, t);
    EXPECT_NEAR(placed.scale, 1.0, 1e-6);
    EXPECT_LT(norm(placed.pose.translation() - truth.translation()), 1e-6);
    EXPECT_LT(rotation_angle_between(placed.pose, truth), 1e-6);
  }

  // The static part: everything real but the cart. The cart alone in its own frame.
  const Mesh still = load_gltf_mesh(file, GltfMeshSelection{"", true});
  EXPECT_EQ(triangles_of_colour(still, cart.material.albedo), 0u);
  SimScene without_cart = scene;
  std::erase_if(without_cart.objects, [](const SimObject& o) { return o.name == "cart"; });
  EXPECT_EQ(still.triangle_count(), real_world_mesh(without_cart).triangle_count());
  SimScene only_cart = scene;
  std::erase_if(only_cart.objects, [](const SimObject& o) { return o.name != "cart"; });
  const size_t cart_triangles = real_world_mesh(only_cart).triangle_count();
  const Mesh alone = load_gltf_mesh(file, GltfMeshSelection{"cart", false});
  EXPECT_EQ(alone.triangle_count(), cart_triangles);
  EXPECT_EQ(triangles_of_colour(alone, cart.material.albedo), alone.triangle_count());
  const Bounds bounds = alone.bounds();
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(bounds.min[c], c == 2 ? 0.0 : -0.5 * (*cart.mesh_size_m)[c], 1e-6) << c;
    EXPECT_NEAR(bounds.max[c], c == 2 ? 0.06 : 0.5 * (*cart.mesh_size_m)[c], 1e-6) << c;
  }
  // The whole scene, as the loader without a selection reads it, holds the cart at its rest pose
  // (the first key's) besides the rest.
  EXPECT_EQ(load_gltf_mesh(file).triangle_count(), still.triangle_count() + cart_triangles);
  fs::remove_all(file.parent_path());
}

TEST(AnimatedSceneExport, ASceneWhoseOnlyRealObjectMovesExportsJustTheNode) {
  const SimScene scene = parse_sim_scene(
      "[[object]]\nname = \"ball\"\nshape = \"sphere\"\nradius_m = 0.1\n"
      "[[object.keyframe]]\ntime_s = 0\nposition = [0, 0, 0.1]\n"
      "[[object.keyframe]]\ntime_s = 1\nposition = [1, 0, 0.1]\nrotation_deg = [0, 0, 90]\n"
      "[[object]]\nname = \"ghost\"\nvirtual = true\n"
      "[[object.keyframe]]\ntime_s = 0\n[[object.keyframe]]\ntime_s = 1\nposition = [0, 1, 0]\n",
      "ball.toml", {});
  const fs::path file = exported(scene, "ball-export");
  const GltfAnimation animation = GltfAnimation::load(file, kSceneAnimationName);
  const std::optional<int> node = animation.find_node("ball");
  ASSERT_TRUE(node.has_value());
  EXPECT_FALSE(animation.find_node("ghost").has_value());  // virtual: not a proxy
  const ScaledPose half = animation.node_pose_at(*node, 0.5);
  EXPECT_LT(norm(half.pose.translation() - Vec3{0.5, 0, 0.1}), 1e-6);
  EXPECT_LT(rotation_angle_between(half.pose, SE3::from_rt({0, 0, 45 * kDeg}, {0, 0, 0})), 1e-6);
  EXPECT_EQ(load_gltf_mesh(file, GltfMeshSelection{"ball", false}).triangle_count(),
            real_world_mesh(scene_at_time(scene, 0)).triangle_count());
  fs::remove_all(file.parent_path());
}

}  // namespace
}  // namespace arpipe::sim
