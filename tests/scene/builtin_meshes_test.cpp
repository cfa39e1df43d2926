// Tests of the procedural meshes: size and placement (base on z = 0, centred in x and y), outward
// normals and winding, and a closed surface (every edge shared by exactly two triangles).
#include "core/scene/builtin_meshes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <utility>

namespace arpipe {
namespace {

Vec3 vertex(const Mesh& mesh, uint32_t index) {
  return {mesh.positions[3 * index], mesh.positions[3 * index + 1], mesh.positions[3 * index + 2]};
}
Vec3 normal(const Mesh& mesh, uint32_t index) {
  return {mesh.normals[3 * index], mesh.normals[3 * index + 1], mesh.normals[3 * index + 2]};
}

// For a convex solid, every face's outward normal points away from an interior point, and the
// winding (counter-clockwise seen from outside) agrees with it.
void expect_outward_and_consistent(const Mesh& mesh, const Vec3& interior) {
  ASSERT_EQ(mesh.indices.size() % 3, 0u);
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3 a = vertex(mesh, mesh.indices[t]), b = vertex(mesh, mesh.indices[t + 1]), c = vertex(mesh, mesh.indices[t + 2]);
    const Vec3 winding = cross(b - a, c - a);
    ASSERT_GT(norm(winding), 0) << "degenerate triangle " << t / 3;
    const Vec3 n = normal(mesh, mesh.indices[t]);
    EXPECT_NEAR(norm(n), 1.0, 1e-6);
    EXPECT_GT(dot(winding, n), 0) << "triangle " << t / 3 << " wound against its normal";
    const Vec3 centroid = (1.0 / 3.0) * (a + b + c);
    EXPECT_GT(dot(centroid - interior, n), 0) << "triangle " << t / 3 << " normal points inwards";
  }
}

// Closed and watertight: with shared positions (welding by value), each undirected edge appears
// in exactly two triangles, once in each direction. Subdivided faces meet their neighbours at the
// same grid points, so this also checks that no T-junctions leave cracks.
void expect_closed(const Mesh& mesh) {
  std::map<std::pair<Vec3, Vec3>, int> directed_edges;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k)
      ++directed_edges[{vertex(mesh, mesh.indices[t + k]), vertex(mesh, mesh.indices[t + (k + 1) % 3])}];
  for (const auto& [edge, count] : directed_edges) {
    EXPECT_EQ(count, 1);
    const auto reverse = directed_edges.find({edge.second, edge.first});
    EXPECT_TRUE(reverse != directed_edges.end() && reverse->second == 1) << "open edge";
  }
}

TEST(BuiltinMeshes, CubeIsSixCentimetresStandingOnZZero) {
  const Mesh cube = make_cube_mesh();
  const Bounds box = cube.bounds();
  // Exact up to float storage of the coordinates.
  EXPECT_NEAR(box.min[0], -0.03, 1e-7);
  EXPECT_NEAR(box.max[0], 0.03, 1e-7);
  EXPECT_NEAR(box.min[1], -0.03, 1e-7);
  EXPECT_NEAR(box.max[1], 0.03, 1e-7);
  EXPECT_EQ(box.min[2], 0.0);
  EXPECT_NEAR(box.max[2], 0.06, 1e-7);
  EXPECT_EQ(cube.triangle_count(), 6u * 8 * 8 * 2);
  ASSERT_EQ(cube.parts.size(), 1u);
  EXPECT_EQ(cube.parts[0].index_count, cube.indices.size());
  expect_outward_and_consistent(cube, {0, 0, 0.03});
  expect_closed(cube);
}

TEST(BuiltinMeshes, PyramidHasItsBaseOnZZeroAndApexAbove) {
  const Mesh pyramid = make_pyramid_mesh();
  const Bounds box = pyramid.bounds();
  EXPECT_NEAR(box.min[0], -0.03, 1e-7);
  EXPECT_NEAR(box.max[0], 0.03, 1e-7);
  EXPECT_NEAR(box.min[1], -0.03, 1e-7);
  EXPECT_NEAR(box.max[1], 0.03, 1e-7);
  EXPECT_EQ(box.min[2], 0.0);
  EXPECT_NEAR(box.max[2], 0.06, 1e-7);
  EXPECT_EQ(pyramid.triangle_count(), 8u * 8 * 2 + 4u * 8 * 8);
  expect_outward_and_consistent(pyramid, {0, 0, 0.01});
  expect_closed(pyramid);
}

// The enclosed volume by the divergence theorem: sum over triangles of a . (b x c) / 6.
double enclosed_volume(const Mesh& mesh) {
  double volume = 0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    volume += dot(vertex(mesh, mesh.indices[t]), cross(vertex(mesh, mesh.indices[t + 1]), vertex(mesh, mesh.indices[t + 2])));
  return volume / 6;
}

TEST(BuiltinMeshes, BoxHasItsSizeAndVolume) {
  const Mesh box_mesh = make_box_mesh({0.10, 0.04, 0.07});
  const Bounds box = box_mesh.bounds();
  EXPECT_NEAR(box.min[0], -0.05, 1e-7);
  EXPECT_NEAR(box.max[1], 0.02, 1e-7);
  EXPECT_EQ(box.min[2], 0.0);
  EXPECT_NEAR(box.max[2], 0.07, 1e-7);
  EXPECT_NEAR(enclosed_volume(box_mesh), 0.10 * 0.04 * 0.07, 1e-9);
  expect_outward_and_consistent(box_mesh, {0, 0, 0.035});
  expect_closed(box_mesh);
}

// An elliptic cylinder of n segments encloses the inscribed polygon's area (n/2 sin(2 pi/n) a b)
// times its height; its side normals are the ellipse's (x/a^2, y/b^2), not the radial direction.
TEST(BuiltinMeshes, CylinderIsClosedWithTheEllipsesNormals) {
  const double a = 0.04, b = 0.025, h = 0.09;
  const int n = 48;
  const Mesh cylinder = make_cylinder_mesh({2 * a, 2 * b, h}, n, 4);
  const Bounds box = cylinder.bounds();
  EXPECT_NEAR(box.max[0], a, 1e-7);
  EXPECT_NEAR(box.max[1], b, 1e-4);  // the polygon's top vertex: n is a multiple of 4
  EXPECT_EQ(box.min[2], 0.0);
  EXPECT_NEAR(box.max[2], h, 1e-7);
  const double polygon_area = 0.5 * n * std::sin(2 * 3.14159265358979323846 / n) * a * b;
  EXPECT_NEAR(enclosed_volume(cylinder), polygon_area * h, 1e-9);
  expect_closed(cylinder);
  for (size_t v = 0; v < cylinder.vertex_count(); ++v) {
    const Vec3 p = vertex(cylinder, static_cast<uint32_t>(v)), m = normal(cylinder, static_cast<uint32_t>(v));
    if (std::abs(m[2]) > 0.5) continue;  // a cap's
    const Vec3 expected = normalized(Vec3{p[0] / (a * a), p[1] / (b * b), 0});
    EXPECT_NEAR(dot(m, expected), 1.0, 1e-6) << "vertex " << v;
  }
}

TEST(BuiltinMeshes, SizedBuiltinsTakeTheirSizeAndOthersIgnoreIt) {
  EXPECT_TRUE(builtin_mesh_is_sized("builtin:box"));
  EXPECT_FALSE(builtin_mesh_is_sized("builtin:cube"));
  const std::optional<Mesh> plane = make_builtin_mesh("builtin:plane", {0.3, 0.2, 5});
  ASSERT_TRUE(plane);
  EXPECT_NEAR(plane->bounds().max[0], 0.15, 1e-7);
  EXPECT_NEAR(plane->bounds().max[1], 0.10, 1e-7);
  EXPECT_EQ(plane->bounds().max[2], 0.0);
  const std::optional<Mesh> cube = make_builtin_mesh("builtin:cube", {1, 1, 1});
  ASSERT_TRUE(cube);
  EXPECT_NEAR(cube->bounds().max[2], 0.06, 1e-7);
  EXPECT_EQ(cube->source, "builtin:cube");
  EXPECT_FALSE(make_builtin_mesh("builtin:nothing", {1, 1, 1}));
}

}  // namespace
}  // namespace arpipe
