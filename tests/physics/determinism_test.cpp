// Replays give the same trajectory: two runs of one scene are bit-identical at every substep, and
// advancing in 30 fps chunks or 25 fps chunks (or 1 ms ones) lands on the same substep states.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "core/scene/builtin_meshes.h"
#include "tests/physics/physics_test_scenes.h"

namespace arpipe {
namespace {

using namespace physics_test;

const int kHz = RigidWorldSettings{}.substep_hz;

// A small scene C: a ball thrown at a box and a cylinder, a tumbling box, a pyramid hull, a cup as
// a triangle collider, and a kinematic paddle sweeping through.
void build_scene(RigidWorld& world) {
  world.add_collider(ground(1.0, 0.8));
  world.add_collider(box_collider({1.0, 0, 0.2}, {0.1, 0.4, 0.2}, 0.7, 0.6));
  ColliderSpec cylinder;
  cylinder.name = "cylinder";
  cylinder.shape = CylinderShape{0.15, 0.3};
  cylinder.T_world_collider = at({0.4, 0.6, 0.3});
  world.add_collider(cylinder);
  ColliderSpec cup;
  cup.name = "cup";
  cup.shape = MeshShape{std::make_shared<Mesh>(make_cup_mesh(0.3, 0.2, 0.2, 0.15)), {1, 1, 1}, MeshCollision::Triangles};
  cup.T_world_collider = at({-0.6, 0, 0});
  world.add_collider(cup);

  RigidBodySpec thrown = ball({0, 0, 0.5}, 0.04, 0.7, 0.4);
  thrown.linear_velocity_mps = {3.0, 0.4, 2.0};
  thrown.angular_velocity_radps = {0, 5, 0};
  world.add_body(thrown);
  RigidBodySpec box;
  box.name = "tumbler";
  box.shape = BoxShape{{0.05, 0.03, 0.02}};
  box.T_world_body = SE3(rotation_from_vector({0.3, 0.2, 0.1}), {0.2, -0.3, 0.6});
  box.linear_velocity_mps = {-0.5, 0.8, 0};
  box.angular_velocity_radps = {3, -2, 1};
  world.add_body(box);
  RigidBodySpec pyramid;
  pyramid.name = "pyramid";
  pyramid.shape = MeshShape{std::make_shared<Mesh>(make_pyramid_mesh()), {1.5, 1.5, 1.5}, MeshCollision::ConvexHull};
  pyramid.T_world_body = SE3(rotation_from_vector({2.0, 0, 0}), {-0.6, 0.05, 0.5});
  world.add_body(pyramid);
  RigidBodySpec paddle;
  paddle.name = "paddle";
  paddle.kind = BodyKind::Kinematic;
  paddle.shape = BoxShape{{0.02, 0.3, 0.05}};
  paddle.track = {{kStartNs, at({0.0, -0.8, 0.05})}, {kStartNs + 2'000'000'000, at({0.0, 0.8, 0.05})}};
  world.add_body(paddle);
}

struct Trace {
  std::vector<int64_t> times;
  std::vector<BodySample> samples;  // bodies per substep
};

// Runs the scene for `seconds`, advancing to the end of each chunk of chunk_ns, and records every
// substep's state (the substep grid: start + floor(k * 1e9 / hz)).
Trace run(int64_t chunk_ns, double seconds) {
  RigidWorld world;
  build_scene(world);
  world.start(kStartNs);
  Trace trace;
  int64_t k = 0;
  const auto end_ns = kStartNs + static_cast<int64_t>(seconds * 1e9);
  for (int64_t t = kStartNs; t < end_ns;) {
    t = std::min(t + chunk_ns, end_ns);
    world.advance_to(t);
    for (;; ++k) {
      const int64_t tk = kStartNs + k * 1'000'000'000 / kHz;
      if (tk > world.newest_ns()) break;
      trace.times.push_back(tk);
      for (size_t b = 0; b < world.body_count(); ++b) trace.samples.push_back(world.sample_at(b, tk));
    }
  }
  return trace;
}

bool same_bits(const BodySample& a, const BodySample& b) {
  return std::memcmp(&a.T_world_body.rotation(), &b.T_world_body.rotation(), sizeof(Mat3)) == 0 &&
         std::memcmp(&a.T_world_body.translation(), &b.T_world_body.translation(), sizeof(Vec3)) == 0 &&
         std::memcmp(&a.linear_velocity_mps, &b.linear_velocity_mps, sizeof(Vec3)) == 0 &&
         std::memcmp(&a.angular_velocity_radps, &b.angular_velocity_radps, sizeof(Vec3)) == 0 &&
         a.present == b.present && !a.clamped && !b.clamped;
}

void expect_identical(const Trace& a, const Trace& b) {
  ASSERT_EQ(a.times, b.times);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i)
    ASSERT_TRUE(same_bits(a.samples[i], b.samples[i])) << "substep " << i / 4 << ", body " << i % 4;
}

constexpr int64_t k30fps = 33'333'333, k25fps = 40'000'000;

TEST(Determinism, TwoRunsGiveBitIdenticalTrajectories) {
  const Trace a = run(k30fps, 3.0), b = run(k30fps, 3.0);
  ASSERT_EQ(a.times.size(), 3u * kHz + 1);
  expect_identical(a, b);
  // Something happened: the thrown ball moved and the bodies are all still in.
  const BodySample& ball_end = a.samples[a.samples.size() - 4];
  EXPECT_GT(norm(ball_end.T_world_body.translation() - Vec3{0, 0, 0.5}), 0.3);
}

TEST(Determinism, FrameRateOfTheAdvancesDoesNotChangeTheSubsteps) {
  const Trace at30 = run(k30fps, 3.0), at25 = run(k25fps, 3.0), at1ms = run(1'000'000, 3.0);
  expect_identical(at30, at25);
  expect_identical(at30, at1ms);
}

TEST(Determinism, TheSubstepGridIsExactIntegerNanoseconds) {
  RigidWorld world;
  world.start(kStartNs);
  world.advance_to(kStartNs + 2'000'000'000);
  EXPECT_EQ(world.newest_ns(), kStartNs + 2'000'000'000);
  EXPECT_EQ(world.stats().substeps, 2 * kHz);
  world.advance_to(kStartNs + 2'000'000'001);
  EXPECT_EQ(world.newest_ns(), kStartNs + 2'000'000'000 + 1'000'000'000 / kHz);
}

}  // namespace
}  // namespace arpipe
