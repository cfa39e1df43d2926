// EmbreeScene: exact analytic hits, closest-hit order, shadow-ray roles, triangles, bad input.
#include "capture/sim/embree_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "capture/sim/sample_rng.h"

namespace arpipe::sim {
namespace {

Vec3 random_unit(SampleRng& rng) {
  const double z = 2 * rng.uniform() - 1, phi = 2 * std::numbers::pi * rng.uniform();
  const double r = std::sqrt(1 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

TEST(EmbreeScene, SphereHitsAreExactInDoublePrecision) {
  EmbreeScene scene;
  const SphereShape sphere{{0.3, -0.2, 0.05}, 0.05};
  const uint32_t id = scene.add_sphere(sphere, {});
  scene.commit();
  SampleRng rng(7, 1);
  for (int i = 0; i < 2000; ++i) {
    // A known surface point p = c + r n, reached by a ray arriving from 1.7 m away.
    const Vec3 n = random_unit(rng);
    Vec3 d = random_unit(rng);
    if (dot(d, n) > -0.05) continue;
    const Vec3 p = sphere.centre + sphere.radius * n;
    const Vec3 origin = p - 1.7 * d;
    const ShapeHit hit = scene.intersect(origin, d);
    ASSERT_TRUE(hit.hit());
    EXPECT_EQ(hit.shape, id);
    // 1e-12: double rounding of a 1.7 m ray (~1e-16 relative); a single-precision sphere
    // (Embree's own) would be off by ~1e-7 m here, and the normal by ~1e-6.
    EXPECT_NEAR(hit.t, 1.7, 1e-12);
    for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(hit.normal[k], n[k], 1e-12);
  }
}

TEST(EmbreeScene, SphereFromInsideHitsTheFarSide) {
  EmbreeScene scene;
  scene.add_sphere({{0, 0, 0}, 2}, {});
  scene.commit();
  const ShapeHit hit = scene.intersect({0.5, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(hit.hit());
  EXPECT_NEAR(hit.t, 1.5, 1e-15);
  EXPECT_NEAR(hit.normal[0], 1, 1e-15);  // outward, as the shape defines it
}

TEST(EmbreeScene, RectangleEdgesAreExact) {
  EmbreeScene scene;
  // Tilted: the axes are a rotation of x, y about z by 30 degrees, then the rectangle sits 0.4 m up.
  const double c = std::cos(0.5236), s = std::sin(0.5236);
  const RectangleShape rect{{0.1, 0.2, 0.4}, {c, s, 0}, {-s, c, 0}, 0.07, 0.03};
  scene.add_rectangle(rect, {});
  scene.commit();
  const Vec3 down{0, 0, -1};
  for (double f : {-1.0, 1.0}) {
    // 1e-9 of the half size inside hits, 1e-9 outside misses: the edge is placed to ~1e-16 m.
    const Vec3 inside = rect.centre + (f * 0.07 * (1 - 1e-9)) * rect.x_axis + Vec3{0, 0, 1};
    const Vec3 outside = rect.centre + (f * 0.07 * (1 + 1e-9)) * rect.x_axis + Vec3{0, 0, 1};
    const ShapeHit hit = scene.intersect(inside, down);
    ASSERT_TRUE(hit.hit());
    EXPECT_NEAR(hit.t, 1.0, 1e-15);
    EXPECT_NEAR(hit.normal[2], 1.0, 1e-15);
    EXPECT_FALSE(scene.intersect(outside, down).hit());
    EXPECT_TRUE(scene.intersect(rect.centre + (f * 0.03 * (1 - 1e-9)) * rect.y_axis + Vec3{0, 0, 1}, down).hit());
    EXPECT_FALSE(scene.intersect(rect.centre + (f * 0.03 * (1 + 1e-9)) * rect.y_axis + Vec3{0, 0, 1}, down).hit());
  }
  // Seen from below: the same rectangle (both faces), its normal still x cross y.
  const ShapeHit below = scene.intersect(rect.centre - Vec3{0, 0, 2}, {0, 0, 1});
  ASSERT_TRUE(below.hit());
  EXPECT_NEAR(below.t, 2.0, 1e-15);
  EXPECT_NEAR(below.normal[2], 1.0, 1e-15);
  // Parallel to it: no hit.
  EXPECT_FALSE(scene.intersect(rect.centre, rect.x_axis).hit());
}

TEST(EmbreeScene, ReturnsTheClosestHitAndHonoursTnearTfar) {
  EmbreeScene scene;
  const uint32_t floor = scene.add_rectangle({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1, 1}, {});
  const uint32_t ball = scene.add_sphere({{0, 0, 0.5}, 0.1}, {});
  const uint32_t lid = scene.add_rectangle({{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 1, 1}, {});
  scene.commit();
  EXPECT_EQ(scene.shape_count(), 3u);
  const Vec3 o{0, 0, 2}, down{0, 0, -1};
  EXPECT_EQ(scene.intersect(o, down).shape, lid);
  ShapeHit hit = scene.intersect(o, down, 1.01);
  EXPECT_EQ(hit.shape, ball);
  EXPECT_NEAR(hit.t, 1.4, 1e-15);
  hit = scene.intersect(o, down, 1.61);
  EXPECT_EQ(hit.shape, floor);
  EXPECT_NEAR(hit.t, 2.0, 1e-15);
  EXPECT_FALSE(scene.intersect(o, down, 0, 0.99).hit());
  // Off the ball: straight to the floor under the lid.
  EXPECT_EQ(scene.intersect({0.5, 0.5, 0.9}, down).shape, floor);
}

TEST(EmbreeScene, RolesSeparateCameraRaysFromShadowRays) {
  EmbreeScene scene;
  const uint32_t seen_only = scene.add_sphere({{0, 0, 1}, 0.1}, {true, false});
  scene.add_sphere({{0, 0, 2}, 0.1}, {false, true});  // a shadow caster the camera never sees
  scene.commit();
  const Vec3 o{0, 0, 0}, up{0, 0, 1};
  const ShapeHit hit = scene.intersect(o, up);
  EXPECT_EQ(hit.shape, seen_only);
  EXPECT_FALSE(scene.intersect({0, 0, 1.5}, up).hit());
  EXPECT_FALSE(scene.occluded(o, up, 0, 1.5));  // the first sphere does not shadow
  EXPECT_TRUE(scene.occluded(o, up));           // the second does
  EXPECT_FALSE(scene.occluded(o, up, 0, 1.85));
  EXPECT_TRUE(scene.occluded(o, up, 0, 1.95));
}

TEST(EmbreeScene, ShadowRaysCanIgnoreOneShape) {
  EmbreeScene scene;
  const uint32_t light = scene.add_sphere({{0, 0, 2}, 0.1}, {});
  scene.commit();
  EXPECT_TRUE(scene.occluded({0, 0, 0}, {0, 0, 1}));
  EXPECT_FALSE(scene.occluded({0, 0, 0}, {0, 0, 1}, 0, kInfinity, light));
}

TEST(EmbreeScene, TrianglesHitWithBarycentricsAndCounterClockwiseNormal) {
  EmbreeScene scene;
  // Two triangles of a unit square in the plane y = 1, front face towards -y.
  std::vector<float> positions{0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1};
  std::vector<uint32_t> indices{0, 1, 2, 2, 1, 3};
  const uint32_t id = scene.add_triangles(positions, indices, {});
  scene.commit();
  const ShapeHit hit = scene.intersect({0.2, -1, 0.3}, {0, 1, 0});
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.shape, id);
  EXPECT_EQ(hit.triangle, 0u);
  // Single-precision triangles: 1e-6 relative.
  EXPECT_NEAR(hit.t, 2.0, 2e-6);
  // p = (1 - b1 - b2) v0 + b1 v1 + b2 v2 with v0 = (0,1,0), v1 = (0,1,1), v2 = (1,1,0).
  EXPECT_NEAR(hit.b1, 0.3, 1e-6);
  EXPECT_NEAR(hit.b2, 0.2, 1e-6);
  // (v1 - v0) x (v2 - v0) = (0,0,1) x (1,0,0) = (0,1,0).
  EXPECT_NEAR(hit.normal[1], 1, 1e-12);
  EXPECT_EQ(scene.intersect({0.8, -1, 0.9}, {0, 1, 0}).triangle, 1u);
  EXPECT_TRUE(scene.occluded({0.5, 0, 0.5}, {0, 1, 0}));
  EXPECT_FALSE(scene.intersect({1.2, -1, 0.5}, {0, 1, 0}).hit());
}

TEST(EmbreeScene, ConcurrentQueriesAgreeWithSerialOnes) {
  EmbreeScene scene;
  scene.add_sphere({{0, 0, 0}, 0.5}, {});
  scene.add_rectangle({{0, 0, -0.5}, {1, 0, 0}, {0, 1, 0}, 2, 2}, {});
  scene.commit();
  std::vector<Vec3> dirs;
  SampleRng rng(11, 2);
  for (int i = 0; i < 4000; ++i) dirs.push_back(random_unit(rng));
  const Vec3 o{0.2, 0.1, 1.5};
  std::vector<double> serial(dirs.size()), parallel(dirs.size());
  for (size_t i = 0; i < dirs.size(); ++i) serial[i] = scene.intersect(o, dirs[i]).t;
  std::vector<std::thread> threads;
  for (size_t k = 0; k < 4; ++k)
    threads.emplace_back([&, k] {
      for (size_t i = k; i < dirs.size(); i += 4) parallel[i] = scene.intersect(o, dirs[i]).t;
    });
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(serial, parallel);
}

TEST(EmbreeScene, RejectsDegenerateShapes) {
  EmbreeScene scene;
  EXPECT_THROW(scene.add_sphere({{0, 0, 0}, 0}, {}), std::invalid_argument);
  EXPECT_THROW(scene.add_sphere({{0, 0, 0}, -1}, {}), std::invalid_argument);
  EXPECT_THROW(scene.add_rectangle({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0, 1}, {}), std::invalid_argument);
  EXPECT_THROW(scene.add_triangles({0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 3}, {}), std::invalid_argument);
  EXPECT_THROW(scene.add_triangles({0, 0, 0, 1, 0}, {0, 1, 2}, {}), std::invalid_argument);
  EXPECT_THROW(scene.add_triangles({0, 0, 0, 1, 0, 0, 0, 1, 0}, {}, {}), std::invalid_argument);
  scene.commit();
  EXPECT_THROW(scene.add_sphere({{0, 0, 0}, 1}, {}), std::logic_error);
  EXPECT_FALSE(scene.intersect({0, 0, 0}, {0, 0, 1}).hit());  // an empty scene is fine
}

}  // namespace
}  // namespace arpipe::sim
