// Tests of the closed-convex check that lets a virtual object skip its shadow lookups: the convex
// builtins pass at any subdivision; a dent, an open surface, a surface wound inside out and the
// cup (concave) fail.
#include "core/scene/mesh_convexity.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/builtin_meshes.h"

namespace arpipe {
namespace {

Mesh builtin(std::string_view source, int subdivisions = 8) {
  std::optional<Mesh> mesh = make_builtin_mesh(source, {0.06, 0.06, 0.06}, subdivisions);
  EXPECT_TRUE(mesh.has_value()) << source;
  return mesh ? *mesh : Mesh{};
}

// Moves every copy of the top face's centre vertex (x = y = 0, z = 6 cm) by dz.
size_t move_top_centre(Mesh& mesh, float dz) {
  size_t moved = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    if (std::abs(mesh.positions[3 * v]) < 1e-7f && std::abs(mesh.positions[3 * v + 1]) < 1e-7f &&
        std::abs(mesh.positions[3 * v + 2] - 0.06f) < 1e-7f) {
      mesh.positions[3 * v + 2] += dz;
      ++moved;
    }
  return moved;
}

TEST(MeshConvexity, ConvexBuiltinsAreClosedAndConvexAtAnySubdivision) {
  for (int subdivisions : {1, 2, 8}) {
    EXPECT_TRUE(is_closed_convex(builtin("builtin:cube", subdivisions))) << subdivisions;
    EXPECT_TRUE(is_closed_convex(builtin("builtin:box", subdivisions))) << subdivisions;
    EXPECT_TRUE(is_closed_convex(builtin("builtin:pyramid", subdivisions))) << subdivisions;
    EXPECT_TRUE(is_closed_convex(builtin("builtin:cylinder", subdivisions))) << subdivisions;
  }
  EXPECT_TRUE(is_closed_convex(*make_builtin_mesh("builtin:sphere")));
}

TEST(MeshConvexity, ADentedCubeIsNotConvexButAStretchedOneIs) {
  Mesh dented = builtin("builtin:cube", 2);
  ASSERT_GT(move_top_centre(dented, -0.01f), 0u);
  EXPECT_FALSE(is_closed_convex(dented));
  Mesh stretched = builtin("builtin:cube", 2);  // the top face raised whole: a taller box
  for (size_t v = 0; v < stretched.vertex_count(); ++v)
    if (stretched.positions[3 * v + 2] > 0.059f) stretched.positions[3 * v + 2] += 0.01f;
  EXPECT_TRUE(is_closed_convex(stretched));
}

TEST(MeshConvexity, OpenInsideOutAndConcaveMeshesAreNot) {
  EXPECT_FALSE(is_closed_convex(builtin("builtin:plane")));  // a surface with a border
  EXPECT_FALSE(is_closed_convex(*make_builtin_mesh("builtin:cup")));
  Mesh open_cube = builtin("builtin:cube", 1);
  open_cube.indices.resize(open_cube.indices.size() - 6);  // one face's two triangles gone
  EXPECT_FALSE(is_closed_convex(open_cube));
  Mesh inside_out = builtin("builtin:cube", 1);
  for (size_t t = 0; t < inside_out.triangle_count(); ++t) std::swap(inside_out.indices[3 * t + 1], inside_out.indices[3 * t + 2]);
  EXPECT_FALSE(is_closed_convex(inside_out));
  EXPECT_FALSE(is_closed_convex(Mesh{}));
}

}  // namespace
}  // namespace arpipe
