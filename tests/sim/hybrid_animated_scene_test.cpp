// configs/sim/hybrid-animated.toml holds what its header comment promises: the proxies-panorama
// world as a 1024 x 512 equirectangular video of 60 frames at 30 fps, a red cart that drives over
// the table in 2 s turning 130 degrees, clear of everything that stands there, which covers the
// cylinder's foot and hides the virtual cube each in the frames the comment names and in no
// other. Visibility is decided by casting rays into the simulator's own geometry at each frame's
// time (scene_at_time, SceneShader), as proxies_scene_test.cpp does. Its export:
// animated_scene_export_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "capture/sim/camera_trajectory.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/sim_scene_loader.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

SimScene hybrid_scene() { return load_sim_scene(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "hybrid-animated.toml"); }

const SimObject& object_named(const SimScene& scene, const std::string& name) {
  for (const auto& object : scene.objects)
    if (object.name == name) return object;
  throw std::runtime_error("no object " + name);
}

// The scene at frame k's time in which exactly the object `marked` counts as virtual (the scene's
// own virtual cube stands in it as a real one), so that sees_virtual_object() says whether a ray's
// first hit is that object.
std::unique_ptr<SceneShader> marking_at(const SimScene& scene, const std::string& marked, int k) {
  SimScene posed = scene_at_time(scene, k / scene.camera.fps);
  for (SimObject& object : posed.objects) object.is_virtual = object.name == marked;
  return std::make_unique<SceneShader>(posed, true);
}

// Points inside an object (base on z = 0, centred) just under its surface where that faces the
// camera: a box's faces on an n x n grid out to their edges, or a cylinder's side and top.
std::vector<Vec3> box_points(const SimObject& object, const Vec3& size, const Vec3& camera, int n) {
  std::vector<Vec3> out;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0}) {
      Vec3 normal{0, 0, 0};
      normal[size_t(axis)] = side;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          Vec3 local{0, 0, size[2] / 2};
          local[size_t(axis)] += side * size[size_t(axis)] * 0.49;
          local[size_t(u)] += size[size_t(u)] * 0.998 * (double(i) / (n - 1) - 0.5);
          local[size_t(v)] += size[size_t(v)] * 0.998 * (double(j) / (n - 1) - 0.5);
          const Vec3 p = object.T_world_object * local;
          if (dot(object.T_world_object.rotate(normal), camera - p) > 0) out.push_back(p);
        }
    }
  return out;
}

std::vector<Vec3> cylinder_points(const SimObject& object, double radius, double height, const Vec3& camera) {
  std::vector<Vec3> out;
  for (int a = 0; a < 72; ++a) {
    const double phi = 2 * kPi * (a + 0.5) / 72;
    const Vec3 normal{std::cos(phi), std::sin(phi), 0};
    for (int h = 0; h < 24; ++h) {
      const Vec3 p = object.T_world_object * Vec3{0.95 * radius * normal[0], 0.95 * radius * normal[1], height * (h + 0.5) / 24};
      if (dot(normal, camera - p) > 0) out.push_back(p);
    }
    for (int r = 1; r <= 4; ++r) out.push_back(object.T_world_object * Vec3{0.2 * r * radius * normal[0], 0.2 * r * radius * normal[1], 0.99 * height});
  }
  return out;
}

// The share of `points` of object `marked` that something else hides from the camera in frame k.
double hidden_share(const SimScene& scene, const std::string& marked, int k, const std::vector<Vec3>& points,
                    const Vec3& camera) {
  const auto shader = marking_at(scene, marked, k);
  int hidden = 0;
  for (const Vec3& p : points) hidden += shader->sees_virtual_object(camera, p - camera) ? 0 : 1;
  return double(hidden) / double(points.size());
}

Vec3 camera_centre(const SimScene& scene) {
  const CameraTrajectory trajectory(scene.trajectory, scene.camera, 3.0, scene.render.seed);
  return trajectory.T_cam_world(0).inverse().translation();
}

TEST(HybridAnimatedScene, AQuarterSizedProxiesPanoramaVideo) {
  const SimScene scene = hybrid_scene();
  const SimScene panorama = load_sim_scene(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "proxies-panorama.toml");
  EXPECT_EQ(scene.camera.model.lensmodel(), "LENSMODEL_LONLAT");
  EXPECT_EQ(scene.camera.model.width(), 1024);
  EXPECT_EQ(scene.camera.model.height(), 512);
  EXPECT_EQ(scene.camera.fps, 30.0);
  EXPECT_EQ(scene.render.frames, 60);
  EXPECT_EQ(camera_centre(scene), camera_centre(panorama));
  // The world of proxies-panorama.toml, object for object and light for light.
  for (const SimObject& expected : panorama.objects) {
    SCOPED_TRACE(expected.name);
    const SimObject& object = object_named(scene, expected.name);
    EXPECT_EQ(object.T_world_object.translation(), expected.T_world_object.translation());
    EXPECT_EQ(object.T_world_object.rotation(), expected.T_world_object.rotation());
    EXPECT_EQ(object.mesh_builtin, expected.mesh_builtin);
    EXPECT_EQ(object.mesh_size_m, expected.mesh_size_m);
    EXPECT_EQ(object.material.albedo, expected.material.albedo);
    EXPECT_TRUE(object.keyframes.empty());
  }
  ASSERT_EQ(scene.lights.size(), panorama.lights.size());
  EXPECT_EQ(scene.lights[0].direction_to_light, panorama.lights[0].direction_to_light);
  EXPECT_EQ(scene.environment.radiance, panorama.environment.radiance);
}

TEST(HybridAnimatedScene, TheCartDrivesOverTheTableIn2SecondsTurning130Degrees) {
  const SimScene scene = hybrid_scene();
  const SimObject& cart = object_named(scene, "cart");
  EXPECT_FALSE(cart.is_virtual);
  EXPECT_EQ(cart.mesh_builtin, "builtin:box");
  EXPECT_EQ(cart.mesh_size_m, (Vec3{0.10, 0.08, 0.06}));
  ASSERT_GE(cart.keyframes.size(), 3u);
  EXPECT_EQ(cart.keyframes.front().time_s, 0.0);
  EXPECT_EQ(cart.keyframes.back().time_s, 2.0);
  EXPECT_NEAR(rotation_angle_between(cart.keyframes.front().T_world_object, cart.keyframes.back().T_world_object),
              130 * kDeg, 1e-12);
  for (const SimObject& other : scene.objects)
    if (other.name != "cart") {
      EXPECT_NE(other.material.albedo, cart.material.albedo) << other.name;
    }
  // The virtual cube of the comment's [[render.objects]].
  const SimObject& cube = object_named(scene, "virtual-cube");
  EXPECT_TRUE(cube.is_virtual);
  EXPECT_EQ(cube.mesh_builtin, "builtin:cube");
  EXPECT_EQ(cube.mesh_scale, 0.4);
  EXPECT_EQ(cube.T_world_object.translation(), (Vec3{-0.145, 0.0, 0.0}));
  EXPECT_EQ(cube.material.albedo, (Rgb{0.8, 0.3, 0.1}));
}

// Whether the point (x, y) on the table lies in the footprint of an object: a box of `size` or the
// cylinder's disc, a little grown.
bool in_box_footprint(const SimObject& object, const Vec3& size, double x, double y, double margin) {
  const Vec3 local = object.T_world_object.inverse() * Vec3{x, y, 0};
  return std::abs(local[0]) <= size[0] / 2 + margin && std::abs(local[1]) <= size[1] / 2 + margin;
}

TEST(HybridAnimatedScene, TheCartStaysOnTheTableClearOfEverythingElse) {
  const SimScene scene = hybrid_scene();
  const Vec3 cart_size{0.10, 0.08, 0.06};
  const double margin = 0.002;
  for (int k = 0; k < scene.render.frames; ++k) {
    SCOPED_TRACE(k);
    const SimScene posed = scene_at_time(scene, k / scene.camera.fps);
    const SimObject& at = object_named(posed, "cart");
    EXPECT_EQ(at.T_world_object.translation()[2], 0.0);  // on z = 0, upright
    EXPECT_NEAR(at.T_world_object.rotation()[2][2], 1.0, 1e-12);
    // The cart's footprint on a grid, against the tag's square, the box's and the cube's footprints
    // and the cylinder's disc.
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 16; ++j) {
        const Vec3 p = at.T_world_object * Vec3{cart_size[0] * (i / 20.0 - 0.5), cart_size[1] * (j / 16.0 - 0.5), 0};
        EXPECT_FALSE(std::abs(p[0]) <= 0.0625 + margin && std::abs(p[1]) <= 0.0625 + margin)
            << "on the tag at " << p[0] << ", " << p[1];
        EXPECT_FALSE(in_box_footprint(object_named(posed, "box"), {0.12, 0.08, 0.10}, p[0], p[1], margin));
        EXPECT_FALSE(in_box_footprint(object_named(posed, "virtual-cube"), {0.024, 0.024, 0.024}, p[0], p[1], margin));
        EXPECT_GT(std::hypot(p[0] - 0.11, p[1] - 0.05), 0.035 + margin) << "in the cylinder";
      }
  }
}

// As seen from the camera: the frames in which the cart hides part of `name`, and how much of it.
std::vector<double> hidden_by_frame(const SimScene& scene, const std::string& name, const std::vector<Vec3>& points) {
  const Vec3 camera = camera_centre(scene);
  std::vector<double> out;
  for (int k = 0; k < scene.render.frames; ++k) out.push_back(hidden_share(scene, name, k, points, camera));
  return out;
}

TEST(HybridAnimatedScene, TheCartCoversTheCylindersFootInFrames11To18) {
  const SimScene scene = hybrid_scene();
  const std::vector<double> hidden =
      hidden_by_frame(scene, "cylinder", cylinder_points(object_named(scene, "cylinder"), 0.035, 0.12, camera_centre(scene)));
  for (int k = 0; k < scene.render.frames; ++k) {
    if (k >= 11 && k <= 18) {
      EXPECT_GT(hidden[size_t(k)], 0.0) << "frame " << k;
    } else {
      EXPECT_EQ(hidden[size_t(k)], 0.0) << "frame " << k;
    }
  }
  EXPECT_GT(hidden[15], 0.2);  // the most: over a fifth of what the camera sees of it
}

TEST(HybridAnimatedScene, TheCartHidesTheVirtualCubeInFrames43To51) {
  const SimScene scene = hybrid_scene();
  const SimObject& cube = object_named(scene, "virtual-cube");
  const std::vector<double> hidden =
      hidden_by_frame(scene, "virtual-cube", box_points(cube, {0.024, 0.024, 0.024}, camera_centre(scene), 8));
  for (int k = 0; k < scene.render.frames; ++k) {
    if (k >= 43 && k <= 51) {
      EXPECT_GT(hidden[size_t(k)], 0.0) << "frame " << k;
    } else {
      EXPECT_EQ(hidden[size_t(k)], 0.0) << "frame " << k;
    }
  }
  EXPECT_EQ(hidden[48], 1.0);  // wholly
  EXPECT_GT(hidden[47], 0.5);
  EXPECT_GT(hidden[49], 0.5);
}

}  // namespace
}  // namespace arpipe::sim
