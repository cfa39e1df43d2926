// configs/sim/proxies.toml holds what its header comment promises: the placements written there
// (which configs/proxies.toml replays), the tag in view and unhidden in every frame, the virtual
// cube partly hidden by the real cylinder in most frames, the cube's shadow on the box's visible
// face and on the floor, and motion blur under 1 px while the camera holds still and several px in
// its swing. Visibility is decided by casting rays into the simulator's own geometry (SceneShader):
// these check the scene's design, not the simulator (ground_truth_coverage_test.cpp does that).
#include <fmt/format.h>
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
#include "capture/sim/sample_rng.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/sim_scene_loader.h"

namespace arpipe::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kExact = 1e-12;

SimScene proxies_scene() {
  return load_sim_scene(fs::path(ARPIPE_SOURCE_DIR) / "configs" / "sim" / "proxies.toml");
}

const SimObject& object_named(const SimScene& scene, const std::string& name) {
  for (const auto& object : scene.objects)
    if (object.name == name) return object;
  throw std::runtime_error("no object " + name);
}

// A world in which exactly the objects `marked` count as virtual, so that sees_virtual_object()
// says whether a ray's first hit is one of them. with_virtual: whether the scene's own virtual
// objects stand in it (as real ones: the composite's world) or are left out (the camera's).
std::unique_ptr<SceneShader> marking(const SimScene& scene, const std::set<std::string>& marked, bool with_virtual) {
  SimScene copy = scene;
  copy.objects.clear();
  for (SimObject object : scene.objects) {
    if (object.is_virtual && !with_virtual && marked.count(object.name) == 0) continue;
    object.is_virtual = marked.count(object.name) != 0;
    copy.objects.push_back(object);
  }
  return std::make_unique<SceneShader>(copy, true);
}

struct Pose {
  SE3 T_cam_world;
  Vec3 centre;
};

// Frame k's poses at exposure start, middle and end (trajectory time 0 = frame 0's exposure start).
struct FramePoses {
  Pose start, mid, end;
};

std::vector<FramePoses> frame_poses(const SimScene& scene) {
  const double exposure_s = scene.camera.exposure_ns.front() * 1e-9;
  const CameraTrajectory trajectory(scene.trajectory, scene.camera, scene.render.frames / scene.camera.fps + 0.1,
                                    scene.render.seed);
  const auto pose = [&](double t) {
    const SE3 T = trajectory.T_cam_world(t);
    return Pose{T, T.inverse().translation()};
  };
  std::vector<FramePoses> out;
  for (int k = 0; k < scene.render.frames; ++k) {
    const double t = k / scene.camera.fps;
    out.push_back({pose(t), pose(t + exposure_s / 2), pose(t + exposure_s)});
  }
  return out;
}

// Points on the faces of a box-shaped object (local size, base on z = 0, centred) that face the
// camera centre, on an n x n grid inset from the edges, with their outward normals (world).
struct SurfacePoint {
  Vec3 p;
  Vec3 n;
};
std::vector<SurfacePoint> box_face_points(const SimObject& object, const Vec3& size, const Vec3& camera, int n) {
  std::vector<SurfacePoint> out;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0}) {
      Vec3 normal_local{0, 0, 0};
      normal_local[size_t(axis)] = side;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          Vec3 local{0, 0, size[2] / 2};
          local[size_t(axis)] += side * size[size_t(axis)] / 2;
          local[size_t(u)] += size[size_t(u)] * 0.9 * ((i + 0.5) / n - 0.5);
          local[size_t(v)] += size[size_t(v)] * 0.9 * ((j + 0.5) / n - 0.5);
          const Vec3 p = object.T_world_object * local;
          const Vec3 normal = object.T_world_object.rotate(normal_local);
          if (dot(normal, camera - p) > 0) out.push_back({p, normal});
        }
    }
  return out;
}

// Largest image motion (px) of the points between a frame's exposure start and end.
double blur_px(const CameraModel& model, const FramePoses& f, const std::vector<Vec3>& points) {
  double largest = 0;
  for (const Vec3& p : points) {
    const auto a = model.project(f.start.T_cam_world * p), b = model.project(f.end.T_cam_world * p);
    if (!a || !b) return 1e9;
    largest = std::max(largest, std::hypot((*a)[0] - (*b)[0], (*a)[1] - (*b)[1]));
  }
  return largest;
}

const Vec3 kBoxSize{0.12, 0.08, 0.10};
const Vec3 kCubeSize{0.072, 0.072, 0.072};  // builtin:cube (6 cm) x mesh_scale 1.2

TEST(ProxiesScene, PlacementsAreThoseOfItsComment) {
  const SimScene scene = proxies_scene();
  const SimObject& box = object_named(scene, "box");
  EXPECT_EQ(box.mesh_builtin, "builtin:box");
  ASSERT_TRUE(box.mesh_size_m);
  EXPECT_EQ(*box.mesh_size_m, kBoxSize);
  EXPECT_EQ(box.T_world_object.translation(), (Vec3{0.315, 0.16, 0.0}));
  EXPECT_NEAR(box.T_world_object.rotation_vector()[2], 20 * kDeg, kExact);
  EXPECT_FALSE(box.is_virtual);
  const SimObject& cylinder = object_named(scene, "cylinder");
  EXPECT_EQ(cylinder.mesh_builtin, "builtin:cylinder");
  ASSERT_TRUE(cylinder.mesh_size_m);
  EXPECT_EQ(*cylinder.mesh_size_m, (Vec3{0.07, 0.07, 0.12}));
  EXPECT_EQ(cylinder.T_world_object.translation(), (Vec3{0.11, 0.05, 0.0}));
  EXPECT_EQ(cylinder.T_world_object.rotation(), identity3());
  EXPECT_FALSE(cylinder.is_virtual);
  const SimObject& cube = object_named(scene, "virtual-cube");
  EXPECT_TRUE(cube.is_virtual);
  EXPECT_EQ(cube.mesh_builtin, "builtin:cube");
  EXPECT_FALSE(cube.mesh_size_m);
  EXPECT_EQ(cube.mesh_scale, 1.2);
  EXPECT_EQ(cube.T_world_object.translation(), (Vec3{0.175, 0.16, 0.0}));
  EXPECT_NEAR(cube.T_world_object.rotation_vector()[2], 15 * kDeg, kExact);
  EXPECT_EQ(cube.material.albedo, (Rgb{0.8, 0.3, 0.1}));
  ASSERT_EQ(scene.lights.size(), 1u);
  const SimLight& sun = scene.lights[0];
  EXPECT_EQ(sun.kind, SimLight::Kind::Directional);
  // Elevation 35 degrees, from -x turned 20 degrees towards +y, to the comment's 4 decimals.
  const Vec3 d{-std::cos(35 * kDeg) * std::cos(20 * kDeg), std::cos(35 * kDeg) * std::sin(20 * kDeg),
               std::sin(35 * kDeg)};
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(sun.direction_to_light[i], d[i], 1e-4);
  EXPECT_EQ(sun.irradiance, 4.0);
  EXPECT_NEAR(sun.angular_diameter_rad, 1.0 * kDeg, kExact);
  EXPECT_EQ(scene.render.frames, 30);
  EXPECT_EQ(scene.camera.exposure_ns, std::vector<int64_t>{4'000'000});
}

TEST(ProxiesScene, TheTagIsInViewAndUnhiddenInEveryFrame) {
  const SimScene scene = proxies_scene();
  const auto tag = marking(scene, {"anchor"}, false);
  const CameraModel& model = scene.camera.model;
  int k = 0;
  for (const FramePoses& f : frame_poses(scene)) {
    SCOPED_TRACE(::testing::Message() << "frame " << k++);
    double margin = 1e9;
    // The whole pattern with its white border (0.125 m), on a 9 x 9 grid.
    for (int i = 0; i <= 8; ++i)
      for (int j = 0; j <= 8; ++j) {
        const Vec3 p{-0.0615 + 0.123 * i / 8, -0.0615 + 0.123 * j / 8, 0};
        for (const Pose* pose : {&f.start, &f.end}) {
          const auto px = model.project(pose->T_cam_world * p);
          ASSERT_TRUE(px);
          margin = std::min({margin, (*px)[0], (*px)[1], 639 - (*px)[0], 479 - (*px)[1]});
        }
        EXPECT_TRUE(tag->sees_virtual_object(f.mid.centre, p - f.mid.centre)) << "tag point " << i << "," << j;
      }
    EXPECT_GT(margin, 20.0) << "px from the image border";
  }
}

TEST(ProxiesScene, TheCylinderHidesPartOfTheCubeInMostFrames) {
  const SimScene scene = proxies_scene();
  const SimObject& cube = object_named(scene, "virtual-cube");
  const auto cube_first = marking(scene, {"virtual-cube"}, true);
  int partly_hidden = 0, k = 0;
  for (const FramePoses& f : frame_poses(scene)) {
    const auto points = box_face_points(cube, kCubeSize, f.mid.centre, 8);
    int hidden = 0;
    for (const SurfacePoint& s : points) hidden += cube_first->sees_virtual_object(f.mid.centre, s.p - f.mid.centre) ? 0 : 1;
    const double fraction = double(hidden) / double(points.size());
    if (fraction > 0.1 && fraction < 0.8) ++partly_hidden;
    else ADD_FAILURE() << "frame " << k << ": " << fraction << " of the cube's visible faces hidden";
    ++k;
  }
  EXPECT_EQ(partly_hidden, scene.render.frames);  // 0.46-0.60 when the scene was made
}

TEST(ProxiesScene, TheCubesShadowFallsOnTheBoxFaceAndTheFloorInView) {
  const SimScene scene = proxies_scene();
  const SimObject& box = object_named(scene, "box");
  const Vec3 to_light = scene.lights[0].direction_to_light;
  const auto cube_first = marking(scene, {"virtual-cube"}, true);
  const auto box_first = marking(scene, {"box"}, true);
  const auto table_first = marking(scene, {"table"}, true);
  int k = 0;
  for (const FramePoses& f : frame_poses(scene)) {
    SCOPED_TRACE(::testing::Message() << "frame " << k);
    int face_lit = 0, face_shadowed = 0;
    for (const SurfacePoint& s : box_face_points(box, kBoxSize, f.mid.centre, 12)) {
      if (s.n[2] > 0.5) continue;  // the top
      if (!box_first->sees_virtual_object(f.mid.centre, s.p - f.mid.centre)) continue;  // hidden (by the cube too)
      (cube_first->sees_virtual_object(s.p + 1e-4 * s.n, to_light) ? face_shadowed : face_lit)++;
    }
    int floor_shadowed = 0;
    for (int i = 0; i < 20; ++i)
      for (int j = 0; j < 20; ++j) {
        const Vec3 p{0.15 + 0.15 * i / 20, 0.0 + 0.25 * j / 20, -0.0005};
        if (table_first->sees_virtual_object(f.mid.centre, p - f.mid.centre) &&
            cube_first->sees_virtual_object(p + Vec3{0, 0, 1e-4}, to_light))
          ++floor_shadowed;
      }
    ++k;  // when the scene was made: 236 lit, 52 in the shadow on the box; 52-57 on the floor
    EXPECT_GE(face_shadowed, 5);
    EXPECT_GE(face_lit, 5);
    EXPECT_GE(floor_shadowed, 5);
  }
}

TEST(ProxiesScene, BlurUnderOnePxWhileStillSeveralPxInTheSwing) {
  const SimScene scene = proxies_scene();
  const SimObject& cube = object_named(scene, "virtual-cube");
  std::vector<Vec3> points;  // the cube's and the tag's corners
  for (double sx : {-0.5, 0.5})
    for (double sy : {-0.5, 0.5}) {
      for (double z : {0.0, 1.0}) points.push_back(cube.T_world_object * Vec3{sx * 0.072, sy * 0.072, z * 0.072});
      points.push_back({sx * 0.125, sy * 0.125, 0});
    }
  int sharp = 0, blurred = 0;
  double most = 0;
  std::string blurs;  // for the failure messages
  for (const FramePoses& f : frame_poses(scene)) {
    const double blur = blur_px(scene.camera.model, f, points);
    blurs += fmt::format(" {:.2f}", blur);
    sharp += blur < 1.0 ? 1 : 0;
    blurred += blur > 3.0 ? 1 : 0;
    most = std::max(most, blur);
  }
  SCOPED_TRACE("blur per frame (px):" + blurs);
  // When the scene was made: 15 frames under 1 px (0-11, 18, 24, 29), 6 over 3 px, at most 4.8 px.
  EXPECT_GE(sharp, 10);
  EXPECT_GE(blurred, 4);
  EXPECT_GT(most, 4.0);
  EXPECT_LT(most, 10.0);
}

}  // namespace
}  // namespace arpipe::sim
