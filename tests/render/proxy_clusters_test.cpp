// Culling clusters of large proxy meshes: every triangle kept exactly once, each cluster's bounds
// holding its triangles, clusters compact in space, small meshes left whole.
#include "render/proxy_clusters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "core/scene/builtin_meshes.h"

namespace arpipe {
namespace {

std::array<uint32_t, 3> sorted_triangle(const Mesh& mesh, size_t t) {
  std::array<uint32_t, 3> tri{mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
  std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());  // keeps the winding
  return tri;
}

TEST(ProxyClusters, EveryTriangleOnceInACompactCluster) {
  const Mesh box = make_box_mesh({0.4, 0.3, 0.2}, 29);  // 10092 triangles
  const ClusteredMesh clustered = cluster_for_culling(box, 256);
  ASSERT_EQ(clustered.mesh.triangle_count(), box.triangle_count());
  ASSERT_EQ(clustered.mesh.parts.size(), clustered.bounds.size());
  EXPECT_EQ(clustered.mesh.parts.size(), (box.triangle_count() + 255) / 256);
  std::multiset<std::array<uint32_t, 3>> before, after;
  for (size_t t = 0; t < box.triangle_count(); ++t) before.insert(sorted_triangle(box, t));
  for (size_t t = 0; t < clustered.mesh.triangle_count(); ++t) after.insert(sorted_triangle(clustered.mesh, t));
  EXPECT_EQ(before, after);
  // Each cluster's triangles inside its bounds, and the parts tile the index list in order.
  uint32_t next = 0;
  for (size_t c = 0; c < clustered.bounds.size(); ++c) {
    const MeshPart& part = clustered.mesh.parts[c];
    EXPECT_EQ(part.first_index, next);
    next += part.index_count;
    const Bounds& b = clustered.bounds[c];
    for (uint32_t i = part.first_index; i < part.first_index + part.index_count; ++i)
      for (size_t axis = 0; axis < 3; ++axis) {
        const float p = clustered.mesh.positions[3 * size_t(clustered.mesh.indices[i]) + axis];
        EXPECT_GE(p, b.min[axis]);
        EXPECT_LE(p, b.max[axis]);
      }
  }
  EXPECT_EQ(next, clustered.mesh.indices.size());
}

// The sum over consecutive chunks of 256 triangles of their bounding box's largest face: how much
// of the picture the chunks would claim, the quantity culling depends on.
double chunk_box_area(const Mesh& mesh) {
  double sum = 0;
  for (size_t first = 0; first < mesh.triangle_count(); first += 256) {
    Bounds b{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t i = 3 * first; i < std::min(mesh.indices.size(), 3 * (first + 256)); ++i)
      for (size_t axis = 0; axis < 3; ++axis) {
        const double p = mesh.positions[3 * size_t(mesh.indices[i]) + axis];
        b.min[axis] = std::min(b.min[axis], p);
        b.max[axis] = std::max(b.max[axis], p);
      }
    const Vec3 size = b.max - b.min;
    sum += std::max({size[0] * size[1], size[1] * size[2], size[0] * size[2]});
  }
  return sum;
}

// A mesh whose triangles come in no spatial order (as a scan's may): in chunks each spans the
// whole box; clustered, each is a patch, and together they claim a small fraction of that.
TEST(ProxyClusters, ClustersAreCompactWhateverTheTriangleOrder) {
  Mesh box = make_box_mesh({0.4, 0.3, 0.2}, 29);
  std::vector<std::array<uint32_t, 3>> triangles;
  for (size_t t = 0; t < box.triangle_count(); ++t)
    triangles.push_back({box.indices[3 * t], box.indices[3 * t + 1], box.indices[3 * t + 2]});
  uint64_t state = 12345;  // a fixed LCG shuffle: the test is the same every run
  for (size_t i = triangles.size() - 1; i > 0; --i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    std::swap(triangles[i], triangles[(state >> 33) % (i + 1)]);
  }
  box.indices.clear();
  for (const auto& tri : triangles) box.indices.insert(box.indices.end(), tri.begin(), tri.end());
  const double shuffled = chunk_box_area(box);
  const double clustered = chunk_box_area(cluster_for_culling(box, 256).mesh);
  std::printf("largest-face areas of 40 chunks: %.3f m^2 shuffled, %.3f m^2 clustered\n", shuffled, clustered);
  EXPECT_LT(clustered, 0.25 * shuffled);
}

TEST(ProxyClusters, ASmallMeshStaysWhole) {
  const Mesh box = make_box_mesh({0.1, 0.1, 0.1}, 1);
  const ClusteredMesh clustered = cluster_for_culling(box, 256);
  EXPECT_TRUE(clustered.bounds.empty());
  EXPECT_EQ(clustered.mesh.indices, box.indices);
}

}  // namespace
}  // namespace arpipe
