// Mesh and primitive shapes against the geometry: a builtin cube as a convex hull rests on its base
// (body frame at z = 0, like the renderer's mesh), a shape offset in the body frame is honoured, a
// cylinder collider's top is where its size says, and a hull's centre of mass is its centroid.
#include <gtest/gtest.h>

#include "core/scene/builtin_meshes.h"
#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

// Tolerances: a body at rest lies on its support within 1 mm (Bullet lets contacts sink by a
// fraction of a millimetre) and keeps its orientation within 5 mrad.
constexpr double kRestTolM = 1e-3;

TEST(MeshShapes, ABuiltinCubeAsAHullRestsOnItsBase) {
  RigidWorld world;
  world.add_collider(ground(0.0, 0.8));
  RigidBodySpec cube;
  cube.name = "cube";
  cube.restitution = 0;
  cube.shape = MeshShape{std::make_shared<Mesh>(make_cube_mesh()), {2, 2, 2}, MeshCollision::ConvexHull};
  cube.T_world_body = at({0.1, 0.2, 0.3});
  const size_t id = world.add_body(cube);
  world.start(kStartNs);
  world.advance_to(kStartNs + 3'000'000'000);
  const SE3 pose = world.pose_at(id, world.newest_ns());
  EXPECT_NEAR(pose.translation()[2], 0.0, kRestTolM);
  EXPECT_NEAR(pose.translation()[0], 0.1, kRestTolM);
  EXPECT_NEAR(pose.translation()[1], 0.2, kRestTolM);
  EXPECT_LT(rotation_angle_between(pose, SE3()), 5e-3);
}

TEST(MeshShapes, AHullFallsFromItsCentreOfMass) {
  // A cube whose mesh sits off its body origin by (0.5, 0, 0): free fall does not turn it.
  RigidWorldSettings settings;
  RigidWorld world(settings);
  Mesh offset = make_cube_mesh(0.1);
  for (size_t v = 0; v < offset.vertex_count(); ++v) offset.positions[3 * v] += 0.5f;
  RigidBodySpec body;
  body.shape = MeshShape{std::make_shared<Mesh>(offset), {1, 1, 1}, MeshCollision::ConvexHull};
  body.T_world_body = at({0, 0, 5});
  body.angular_velocity_radps = {0, 0, 2};  // about the centre of mass, which stays on x = 0.5
  const size_t id = world.add_body(body);
  world.start(kStartNs);
  world.advance_to(kStartNs + 500'000'000);
  const SE3 pose = world.pose_at(id, world.newest_ns());
  const Vec3 com = pose * Vec3{0.5, 0, 0.05};
  EXPECT_NEAR(com[0], 0.5, 1e-4);
  EXPECT_NEAR(com[1], 0.0, 1e-4);
}

TEST(MeshShapes, AShapeOffsetPutsABuiltinSphereOnTheGround) {
  RigidWorld world;
  world.add_collider(ground(0.0, 0.8));
  RigidBodySpec sphere = ball({0, 0, 0.5}, 0.03, 0.0);
  sphere.T_body_shape = at({0, 0, 0.03});  // builtin:sphere: base on z = 0, centre at (0, 0, r)
  const size_t id = world.add_body(sphere);
  world.start(kStartNs);
  world.advance_to(kStartNs + 2'000'000'000);
  EXPECT_NEAR(world.pose_at(id, world.newest_ns()).translation()[2], 0.0, kRestTolM);
}

TEST(MeshShapes, ABallLandsOnACylinderTop) {
  RigidWorld world;
  ColliderSpec cylinder;
  cylinder.name = "stool";
  cylinder.shape = CylinderShape{0.15, 0.3};
  cylinder.T_world_collider = at({0, 0, 0.3});  // top at z = 0.6
  world.add_collider(cylinder);
  const double r = 0.04, h = 0.5;
  const size_t id = world.add_body(ball({0.05, 0, 0.6 + h + r}, r, 0.0));
  double landing_s = -1;
  each_substep(world, 1.5, [&](int64_t t) {
    if (landing_s < 0 && world.sample_at(id, t).T_world_body.translation()[2] - r <= 0.6) landing_s = seconds_since_start(t);
  });
  EXPECT_NEAR(landing_s, std::sqrt(2 * h / kG), 1.0 / RigidWorldSettings{}.substep_hz);
  EXPECT_NEAR(world.pose_at(id, world.newest_ns()).translation()[2], 0.6 + r, kRestTolM);
}

TEST(MeshShapes, ATriangleColliderFromABuiltinCupCatchesABall) {
  RigidWorld world;
  world.add_collider(ground(0.0, 0.8));
  ColliderSpec cup;
  cup.name = "cup";
  // 30 cm across, a pit 20 cm wide and 15 cm deep: the ball falls into the pit and stays there.
  cup.shape = MeshShape{std::make_shared<Mesh>(make_cup_mesh(0.3, 0.2, 0.2, 0.15)), {1, 1, 1}, MeshCollision::Triangles};
  world.add_collider(cup);
  const size_t id = world.add_body(ball({0.02, 0.01, 0.6}, 0.04, 0.3));
  world.start(kStartNs);
  world.advance_to(kStartNs + 3'000'000'000);
  const Vec3 p = world.pose_at(id, world.newest_ns()).translation();
  EXPECT_NEAR(p[2], 0.2 - 0.15 + 0.04, 2e-3);  // on the pit's floor
  EXPECT_LT(std::abs(p[0]), 0.1);
  EXPECT_LT(std::abs(p[1]), 0.1);
}

}  // namespace
}  // namespace arpipe
