// Longest-edge bisection against what it promises: every edge within the limit, the same surface
// (area and bounds), shared edges cut alike (a closed mesh stays closed), parts kept in order, and
// the triangle cap honoured by a longer edge.
#include "core/scene/mesh_subdivide.h"

#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "core/scene/builtin_meshes.h"
#include "core/scene/mesh_weld.h"

namespace arpipe {
namespace {

double area(const Mesh& mesh) {
  double sum = 0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    const auto p = [&](size_t k) {
      const uint32_t v = mesh.indices[t + k];
      return Vec3{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
    };
    sum += 0.5 * norm(cross(p(1) - p(0), p(2) - p(0)));
  }
  return sum;
}

double longest_edge(const Mesh& mesh) {
  double longest = 0;
  for (size_t t = 0; t < mesh.indices.size(); t += 3)
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
      longest = std::max(longest, norm(Vec3{mesh.positions[3 * a] - mesh.positions[3 * b], mesh.positions[3 * a + 1] - mesh.positions[3 * b + 1],
                                            mesh.positions[3 * a + 2] - mesh.positions[3 * b + 2]}));
    }
  return longest;
}

TEST(MeshSubdivide, EveryEdgeWithinTheLimitOnTheSameSurface) {
  const Mesh box = make_box_mesh({2.0, 1.0, 0.5}, 1);
  const Mesh cut = subdivided(box, 0.1);
  EXPECT_LE(longest_edge(cut), 0.1 + 1e-6);
  EXPECT_NEAR(area(cut), area(box), 1e-4 * area(box));
  EXPECT_EQ(cut.bounds().min, box.bounds().min);
  EXPECT_EQ(cut.bounds().max, box.bounds().max);
  ASSERT_EQ(cut.normals.size(), cut.positions.size());
  ASSERT_EQ(cut.parts.size(), box.parts.size());
  EXPECT_EQ(cut.parts.back().first_index + cut.parts.back().index_count, cut.indices.size());
}

TEST(MeshSubdivide, SharedEdgesAreCutAlikeSoAClosedSurfaceStaysClosed) {
  // The builtin sphere repeats its seam's and poles' vertices (their own normals); welded (to a
  // micrometre) it is closed. Cut, both sides of every edge get the same midpoints, so welded
  // again it is still closed: no crack anywhere.
  const Mesh sphere = make_sphere_mesh(1.0, 6);
  ASSERT_EQ(count_unpaired_edges(weld_by_position(sphere, 1e-6)), 0u);
  const Mesh cut = subdivided(sphere, 0.2);
  EXPECT_GT(cut.triangle_count(), 4 * sphere.triangle_count());
  EXPECT_LE(longest_edge(cut), 0.2 + 1e-6);
  EXPECT_EQ(count_unpaired_edges(weld_by_position(cut, 1e-6)), 0u);
  EXPECT_NEAR(area(cut), area(sphere), 1e-4 * area(sphere));
}

TEST(MeshSubdivide, TheTriangleCapLengthensTheEdge) {
  const Mesh plane = make_rectangle_mesh(100.0, 100.0, 1);
  double used = 0;
  const Mesh cut = subdivided(plane, 0.1, 10'000, &used);
  EXPECT_GT(used, 0.1);
  EXPECT_LE(cut.triangle_count(), 10'000u * 2);
  EXPECT_LE(longest_edge(cut), used + 1e-3);
}

TEST(MeshSubdivide, CarriedValuesAreWhatTheRasteriserInterpolatesThere) {
  // Two values a vertex, linear in the position (2x + 3y - z, and x): the mean of an edge's ends
  // at its midpoint is that function there, so every new vertex holds the function's value (the
  // shading a PRT transfer gives stays as it was). The geometry is the same cut as without values.
  const Mesh box = make_box_mesh({0.5, 0.3, 0.2}, 1);
  std::vector<float> values;
  const auto f = [](const float* p) { return std::array<float, 2>{2 * p[0] + 3 * p[1] - p[2], p[0]}; };
  for (size_t v = 0; v < box.vertex_count(); ++v) {
    const auto value = f(&box.positions[3 * v]);
    values.insert(values.end(), value.begin(), value.end());
  }
  const Mesh cut = subdivided(box, values, 2, 0.05);
  const Mesh plain = subdivided(box, 0.05);
  EXPECT_EQ(cut.positions, plain.positions);
  EXPECT_EQ(cut.indices, plain.indices);
  ASSERT_EQ(values.size(), 2 * cut.vertex_count());
  ASSERT_GT(cut.vertex_count(), box.vertex_count());
  for (size_t v = 0; v < cut.vertex_count(); ++v) {
    const auto expected = f(&cut.positions[3 * v]);
    EXPECT_NEAR(values[2 * v], expected[0], 1e-5) << "vertex " << v;
    EXPECT_NEAR(values[2 * v + 1], expected[1], 1e-6) << "vertex " << v;
  }
  std::vector<float> wrong(3);
  EXPECT_THROW(subdivided(box, wrong, 2, 0.05), std::invalid_argument);
}

}  // namespace
}  // namespace arpipe
