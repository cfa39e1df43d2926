// Hostile specs get a PhysicsError (an std::invalid_argument) naming the item, its index and the
// field; a refused item leaves the world unchanged; the declared limits hold.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "core/physics/physics_error.h"
#include "core/physics/physics_limits.h"
#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The message names everything in `parts`.
template <class F>
void expect_error_naming(F&& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const PhysicsError& e) {
    const std::string message = e.what();
    for (const std::string& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message << "\nlacks: " << part;
  }
}

void expect_body_error(const RigidBodySpec& spec, const std::string& field) {
  RigidWorld world;
  world.add_body(ball({0, 0, 1}, 0.05, 0.5));  // so the bad one is index 1
  expect_error_naming([&] { world.add_body(spec); }, {"body 1", "\"" + spec.name + "\"", field});
  EXPECT_EQ(world.body_count(), 1u);
}

RigidBodySpec good_ball() { return ball({0, 0, 1}, 0.05, 0.5); }

TEST(BadSpec, BodyNumbers) {
  RigidBodySpec s = good_ball();
  s.mass_kg = 0;
  expect_body_error(s, "mass_kg");
  s.mass_kg = -1;
  expect_body_error(s, "mass_kg");
  s.mass_kg = kNaN;
  expect_body_error(s, "mass_kg");
  s = good_ball();
  s.linear_velocity_mps = {kInf, 0, 0};
  expect_body_error(s, "linear_velocity_mps");
  s = good_ball();
  s.angular_velocity_radps = {0, kNaN, 0};
  expect_body_error(s, "angular_velocity_radps");
  s = good_ball();
  s.restitution = 1.5;
  expect_body_error(s, "restitution");
  s = good_ball();
  s.friction = -0.1;
  expect_body_error(s, "friction");
  s = good_ball();
  s.rolling_friction = kNaN;
  expect_body_error(s, "rolling_friction");
  s = good_ball();
  s.linear_damping = 2;
  expect_body_error(s, "linear_damping");
}

TEST(BadSpec, StaticAndKinematicBodiesNeedNoMass) {
  RigidWorld world;
  RigidBodySpec s = good_ball();
  s.mass_kg = 0;
  s.kind = BodyKind::Static;
  EXPECT_NO_THROW(world.add_body(s));
  s.kind = BodyKind::Kinematic;
  EXPECT_NO_THROW(world.add_body(s));
}

TEST(BadSpec, Sizes) {
  RigidBodySpec s = good_ball();
  s.shape = SphereShape{0};
  expect_body_error(s, "shape.radius_m");
  s.shape = SphereShape{-1};
  expect_body_error(s, "shape.radius_m");
  s.shape = BoxShape{{0.1, kNaN, 0.1}};
  expect_body_error(s, "shape.half_extents_m");
  s.shape = CylinderShape{0.1, 0};
  expect_body_error(s, "shape.half_height_m");
  s.shape = SphereShape{1e9};
  expect_body_error(s, "shape.radius_m");
}

TEST(BadSpec, Poses) {
  RigidBodySpec s = good_ball();
  s.T_world_body = at({0, kNaN, 0});
  expect_body_error(s, "T_world_body");
  s.T_world_body = SE3(Mat3{{{2, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, {0, 0, 1});
  expect_body_error(s, "T_world_body");
  s.T_world_body = SE3(Mat3{{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, {0, 0, 1});  // a reflection
  expect_body_error(s, "T_world_body");
  s = good_ball();
  s.T_body_shape = at({kInf, 0, 0});
  expect_body_error(s, "T_body_shape");
}

TEST(BadSpec, Tracks) {
  RigidBodySpec s = good_ball();
  s.track = {{0, at({0, 0, 1})}};
  expect_body_error(s, "track");  // a dynamic body with a track
  s.kind = BodyKind::Kinematic;
  s.track = {{10, at({0, 0, 1})}, {10, at({0, 0, 2})}};
  expect_body_error(s, "track[1]");
  s.track = {{10, at({0, 0, 1})}, {20, at({0, kNaN, 2})}};
  expect_body_error(s, "track[1]");
}

std::shared_ptr<Mesh> mesh_of(std::vector<float> positions, std::vector<uint32_t> indices, std::string source = "") {
  auto m = std::make_shared<Mesh>();
  m->positions = std::move(positions);
  m->indices = std::move(indices);
  m->source = std::move(source);
  return m;
}

std::shared_ptr<Mesh> tetrahedron() { return mesh_of({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}); }

void expect_collider_error(const ColliderSpec& spec, std::initializer_list<std::string> parts) {
  RigidWorld world;
  world.add_collider(ground());
  std::vector<std::string> all{"collider 1", "\"" + spec.name + "\""};
  all.insert(all.end(), parts.begin(), parts.end());
  try {
    world.add_collider(spec);
    ADD_FAILURE() << "no error";
  } catch (const PhysicsError& e) {
    for (const std::string& part : all) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what() << "\nlacks: " << part;
  }
  EXPECT_EQ(world.collider_count(), 1u);
  EXPECT_EQ(world.stats().triangles, 0u);
}

ColliderSpec mesh_collider(std::shared_ptr<Mesh> mesh, MeshCollision collision = MeshCollision::Triangles) {
  ColliderSpec c;
  c.name = "table";
  c.shape = MeshShape{std::move(mesh), {1, 1, 1}, collision};
  return c;
}

TEST(BadSpec, Meshes) {
  expect_collider_error(mesh_collider(nullptr), {"shape.mesh", "no mesh"});
  expect_collider_error(mesh_collider(mesh_of({}, {}, "proxies/table.glb")), {"proxies/table.glb", "empty"});
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0}, {})), {"not three per vertex"});
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 0, 1, 0}, {})), {"no triangles"});
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 7})), {"triangle 0", "vertex 7"});
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 0, std::nanf(""), 0}, {0, 1, 2}, "a.glb")),
                        {"a.glb", "vertex 2", "non-finite"});
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 2, 0, 0}, {0, 1, 2})), {"degenerate"});
  // Three triangles on one edge (0-1): not manifold.
  expect_collider_error(
      mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1}, {0, 1, 2, 1, 0, 3, 0, 1, 4}, "shelf.glb")),
      {"shelf.glb", "not manifold", "more than two triangles"});
  // A flat hull.
  expect_collider_error(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, {0, 1, 2}), MeshCollision::ConvexHull),
                        {"no volume"});
  ColliderSpec scaled = mesh_collider(tetrahedron());
  std::get<MeshShape>(scaled.shape).scale = {1, 0, 1};
  expect_collider_error(scaled, {"shape.scale"});
}

TEST(BadSpec, DegenerateTrianglesAreSkippedAndCounted) {
  RigidWorld world;
  // Two real triangles and one with a repeated corner.
  world.add_collider(mesh_collider(mesh_of({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 1, 2, 0, 2, 3, 0, 0, 1})));
  EXPECT_EQ(world.stats().degenerate_triangles, 1u);
  EXPECT_EQ(world.stats().triangles, 3u);
}

TEST(BadSpec, ADynamicBodyCannotCollideAsTriangles) {
  RigidBodySpec s = good_ball();
  s.shape = MeshShape{tetrahedron(), {1, 1, 1}, MeshCollision::Triangles};
  expect_body_error(s, "shape.collision");
  s.kind = BodyKind::Kinematic;
  RigidWorld world;
  EXPECT_NO_THROW(world.add_body(s));
}

TEST(BadSpec, ColliderNumbers) {
  ColliderSpec c = box_collider({0, 0, 0}, {0.1, 0.1, 0.1});
  c.name = "table";
  c.restitution = kNaN;
  expect_collider_error(c, {"restitution"});
  c = box_collider({0, 0, 0}, {0.1, -0.1, 0.1});
  c.name = "table";
  expect_collider_error(c, {"shape.half_extents_m"});
  c = box_collider({0, 0, 1e7}, {0.1, 0.1, 0.1});
  c.name = "table";
  expect_collider_error(c, {"T_world_collider"});
}

TEST(BadSpec, Settings) {
  auto expect_settings_error = [](RigidWorldSettings s, const std::string& field) {
    expect_error_naming([&] { RigidWorld world(s); }, {"physics settings", field});
  };
  RigidWorldSettings s;
  s.substep_hz = 0;
  expect_settings_error(s, "substep_hz");
  s = {};
  s.max_substeps_per_advance = 0;
  expect_settings_error(s, "max_substeps_per_advance");
  s = {};
  s.history_ns = -1;
  expect_settings_error(s, "history_ns");
  s = {};
  s.gravity_mps2 = {0, 0, kNaN};
  expect_settings_error(s, "gravity_mps2");
  s = {};
  s.world_radius_m = 0;
  expect_settings_error(s, "world_radius_m");
}

TEST(BadSpec, CountLimits) {
  RigidWorld world;
  for (size_t i = 0; i < physics_limits::kMaxBodies; ++i) world.add_body(ball({0.2 * static_cast<double>(i), 0, 1}, 0.05, 0.5));
  expect_error_naming([&] { world.add_body(good_ball()); }, {"body 1024", "limit of 1024 bodies"});
  // A mesh over the triangle limit is refused before anything is built.
  auto big = std::make_shared<Mesh>();
  big->positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  big->indices.assign(3 * (physics_limits::kMaxTrianglesPerMesh + 1), 0);
  expect_collider_error(mesh_collider(big), {"more than the limit"});
}

TEST(BadSpec, PhysicsErrorIsAnInvalidArgument) {
  RigidWorld world;
  RigidBodySpec s = good_ball();
  s.mass_kg = -1;
  EXPECT_THROW(world.add_body(s), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe
