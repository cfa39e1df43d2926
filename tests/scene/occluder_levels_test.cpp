// Tests of the occluders' coarser levels: a finely tessellated cylinder (slivers) gets levels of
// at most half the triangles each, whose silhouettes stay within the error they state, projected;
// a subdivided box becomes its 12 triangles with no error; small meshes get none; the level chosen
// for a depth and a tolerance is the coarsest that fits.
#include "core/scene/occluder_levels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/scene/builtin_meshes.h"
#include "core/scene/silhouette_views.h"

namespace arpipe {
namespace {

TEST(OccluderLevels, SliverCylinderGetsHalvingLevelsWhoseSilhouettesStayWithinTheirStatedError) {
  // The benchmark's 10k-triangle cylinder: 420 segments, long slivers on the side.
  Mesh cylinder = make_cylinder_mesh({0.08, 0.08, 0.12}, 420, 4);
  cylinder.source = "cylinder";
  const std::vector<OccluderLevel> levels = make_occluder_levels(cylinder);
  ASSERT_FALSE(levels.empty());
  size_t previous = cylinder.triangle_count();
  for (const OccluderLevel& level : levels) {
    EXPECT_LE(2 * level.mesh->triangle_count(), previous);
    previous = level.mesh->triangle_count();
    EXPECT_GE(level.error, 0.0);
  }
  // Tenfold fewer at the coarsest level at least: a 420-gon is close to a 48-gon (0.2 % of its
  // radius) long before it is a hexagon.
  EXPECT_LE(10 * levels.back().mesh->triangle_count(), cylinder.triangle_count());

  // Each level's silhouette against the full mesh's, from 26 views at the default distance: the
  // mean edge displacement is at most the stated error projected at the nearest possible depth
  // (the distance less the bounding radius), plus the rasteriser's 1/8 px of quantisation.
  const CameraModel camera = default_silhouette_camera();
  const Bounds box = cylinder.bounds();
  const double distance = *default_view_distance_m(box, camera);
  const double nearest = distance - bounding_radius_m(box);
  for (const OccluderLevel& level : levels) {
    const SilhouetteComparison comparison =
        compare_silhouettes(cylinder, *level.mesh, camera, cube_views_around(box, distance));
    const double bound = camera.fx() * level.error / nearest + 0.125;
    EXPECT_LE(comparison.max_error_px, bound) << level.mesh->triangle_count() << " triangles, error " << level.error
                                              << " m, worst view " << comparison.worst_view;
    std::printf("level of %zu triangles, error %.3g mm: silhouette %.3f px, bound %.3f px\n", level.mesh->triangle_count(),
                1e3 * level.error, comparison.max_error_px, bound);
    RecordProperty("triangles_" + std::to_string(level.mesh->triangle_count()),
                   std::to_string(comparison.max_error_px) + " px of " + std::to_string(bound));
  }
}

TEST(OccluderLevels, SubdividedBoxBecomesTwelveTrianglesWithNoError) {
  const Mesh box = make_box_mesh({0.1, 0.2, 0.3}, 29);  // 10092 triangles
  const std::vector<OccluderLevel> levels = make_occluder_levels(box);
  ASSERT_FALSE(levels.empty());
  const Mesh& coarsest = *levels.back().mesh;
  EXPECT_EQ(coarsest.triangle_count(), 12u);
  // The faces are planes: what is left are the corners, exactly.
  for (size_t v = 0; v < coarsest.vertex_count(); ++v)
    for (size_t axis = 0; axis < 3; ++axis) {
      const double x = coarsest.positions[3 * v + axis];
      EXPECT_TRUE(std::abs(x - box.bounds().min[axis]) < 1e-7 || std::abs(x - box.bounds().max[axis]) < 1e-7) << x;
    }
}

TEST(OccluderLevels, SmallMeshesGetNone) {
  EXPECT_TRUE(make_occluder_levels(make_box_mesh({0.1, 0.1, 0.1}, 1)).empty());  // 12 triangles
  EXPECT_TRUE(make_occluder_levels(make_cylinder_mesh({0.1, 0.1, 0.1}, 8, 1)).empty());
}

TEST(OccluderLevels, ChoosesTheCoarsestLevelThatFits) {
  const std::vector<double> errors{0.0001, 0.001, 0.01};  // m
  // 500 px focal length at 1 m: 0.05, 0.5 and 5 px.
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 1.0, 0.1), 0);
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 1.0, 0.5), 1);
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 1.0, 10), 2);
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 1.0, 0.01), -1);  // none fits: the full mesh
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 0.1, 0.1), -1);   // ten times nearer: 0.5 px at best
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 1.0, 0), -1);     // tolerance 0: the full mesh
  EXPECT_EQ(coarsest_occluder_level(errors, 500, 0.0, 1), -1);     // at the eye
  EXPECT_EQ(coarsest_occluder_level(errors, 500, -1.0, 1), -1);    // behind it
  EXPECT_EQ(coarsest_occluder_level(errors, 500, NAN, 1), -1);
  EXPECT_EQ(coarsest_occluder_level({}, 500, 1.0, 1), -1);
}

}  // namespace
}  // namespace arpipe
