// Tests of the silhouette masks and their edge error against closed forms: areas of drawn squares
// and circles, edge lengths, and the error of shifted and grown shapes.
#include "core/scene/silhouette_raster.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/scene/builtin_meshes.h"
#include "core/scene/silhouette_views.h"

namespace arpipe {
namespace {

// The coverage's 0.5 contour (marching squares between pixel centres) cuts a sharp corner short by
// at most (2 - sqrt 2) px: a square's edge measures up to 4 (2 - sqrt 2) = 2.34 px short.
const double kSquareCornerCuts = 4 * (2 - std::sqrt(2.0));

// An error measured over a square's edge (perimeter_px long): the corner cuts shorten the length it
// is divided by, so the error is the closed form's, or up to perimeter / (perimeter - cuts) more.
void expect_within_corner_cuts(double error_px, double expected_px, double perimeter_px) {
  EXPECT_GE(error_px, expected_px * (1 - 1e-12));
  EXPECT_LE(error_px, expected_px * perimeter_px / (perimeter_px - kSquareCornerCuts));
}

void fill_rectangle(SilhouetteMask& mask, double x0, double y0, double x1, double y1) {
  mask.fill_triangle({x0, y0}, {x1, y0}, {x1, y1});
  mask.fill_triangle({x0, y0}, {x1, y1}, {x0, y1});
}

// A regular polygon of many sides as a fan: a circle to within r (1 - cos(pi / n)).
void fill_disc(SilhouetteMask& mask, double cx, double cy, double r, int sides = 2048) {
  for (int k = 0; k < sides; ++k) {
    const double a0 = 2 * std::numbers::pi * k / sides, a1 = 2 * std::numbers::pi * (k + 1) / sides;
    mask.fill_triangle({cx, cy}, {cx + r * std::cos(a0), cy + r * std::sin(a0)}, {cx + r * std::cos(a1), cy + r * std::sin(a1)});
  }
}

TEST(SilhouetteRaster, SquareCoversItsAreaAndItsEdgeIsItsPerimeter) {
  // Pixel coordinates are mrcal's (pixel centres on integers); samples sit at k/4 - 3/8, so
  // edges on whole and half pixels fall between samples: the area is exact.
  SilhouetteMask mask(200, 160, 4);
  fill_rectangle(mask, 40.0, 30.0, 140.0, 130.0);
  EXPECT_DOUBLE_EQ(mask.area_px(), 100.0 * 100.0);
  const double length = silhouette_edge_length_px(mask);
  EXPECT_LE(length, 400.0 + 1e-9);
  EXPECT_GE(length, 400.0 - kSquareCornerCuts);
}

TEST(SilhouetteRaster, EitherWindingAndSharedEdgesLeaveNoGap) {
  SilhouetteMask ccw(64, 64, 4), cw(64, 64, 4);
  fill_rectangle(ccw, 10.3, 10.3, 50.7, 40.1);
  cw.fill_triangle({10.3, 10.3}, {50.7, 40.1}, {50.7, 10.3});
  cw.fill_triangle({10.3, 10.3}, {10.3, 40.1}, {50.7, 40.1});
  EXPECT_EQ(ccw.symmetric_difference_px(cw), 0.0);
  // 40.4 x 29.8 px within one sample row or column per side (0.25 px each way).
  EXPECT_NEAR(ccw.area_px(), 40.4 * 29.8, 0.25 * (40.4 + 29.8) * 2);
  SilhouetteMask degenerate(64, 64, 4);
  degenerate.fill_triangle({1, 1}, {30, 30}, {60, 60});                    // no area
  degenerate.fill_triangle({1, 1}, {std::nan(""), 30}, {60, 2});           // not finite
  degenerate.fill_triangle({-1e300, -1e300}, {-1e300, 1e300}, {-2e300, 0});  // far outside
  EXPECT_EQ(degenerate.covered_samples(), 0u);
}

TEST(SilhouetteRaster, DiscCoversPiRSquaredAndItsEdgeIsTwoPiR) {
  SilhouetteMask mask(300, 300, 4);
  const double r = 100;
  fill_disc(mask, 150.2, 149.7, r);
  // The 2048-gon's area is pi r^2 (1 - O(1e-6)); sampling adds noise of about a sample per
  // sample row crossing the edge: 0.5 px^2 here. 5 px^2 of 31416 is 1.6e-4.
  EXPECT_NEAR(mask.area_px(), std::numbers::pi * r * r, 5.0);
  // The contour through linearly interpolated coverage wavers a little about a slanted edge (the
  // coverage is quantised to 1/16 and is not linear across the edge): 0.4 % long here; 1 % allowed.
  EXPECT_NEAR(silhouette_edge_length_px(mask), 2 * std::numbers::pi * r, 0.01 * 2 * std::numbers::pi * r);
}

// A straight edge moved across itself by d: the error is d (the image's border is no edge).
TEST(SilhouetteRaster, HalfPlaneShiftedByHalfAPixelHasHalfAPixelOfError) {
  SilhouetteMask before(120, 80, 4), after(120, 80, 4);
  fill_rectangle(before, -10, -10, 60.0, 100);
  fill_rectangle(after, -10, -10, 60.5, 100);
  const SilhouetteEdgeError error = silhouette_edge_error(before, after);
  EXPECT_DOUBLE_EQ(error.difference_px2, 0.5 * 80);
  EXPECT_NEAR(error.edge_length_px, 79.0, 1e-9);  // between the first and last rows' pixel centres
  // 0.5 * 80 / 79: the contour stops at the outer pixel centres, half a pixel short at each end.
  EXPECT_NEAR(error.error_px, 0.5, 0.5 * 1.5 / 80);
}

// A square of side L shifted by d along x: the strips on its left and right edges, 2 d L, over its
// perimeter 4 L: d / 2 (the top and bottom edges slide along themselves and do not count).
TEST(SilhouetteRaster, SquareShiftedAlongXHasHalfTheShiftOfError) {
  SilhouetteMask before(200, 160, 4), after(200, 160, 4);
  fill_rectangle(before, 40.0, 30.0, 140.0, 130.0);
  fill_rectangle(after, 40.5, 30.0, 140.5, 130.0);
  const SilhouetteEdgeError error = silhouette_edge_error(before, after);
  EXPECT_DOUBLE_EQ(error.difference_px2, 2 * 0.5 * 100);
  expect_within_corner_cuts(error.error_px, 0.25, 400);
}

// Grown by d on every side: ((L + 2d)^2 - L^2) / 4L = d + d^2 / L; a disc grown by d: d (1 + d / 2r).
TEST(SilhouetteRaster, ShapesGrownByHalfAPixelHaveHalfAPixelOfError) {
  SilhouetteMask square(200, 160, 4), grown_square(200, 160, 4);
  fill_rectangle(square, 40.0, 30.0, 140.0, 130.0);
  fill_rectangle(grown_square, 39.5, 29.5, 140.5, 130.5);
  expect_within_corner_cuts(silhouette_edge_error(square, grown_square).error_px, 0.5 + 0.25 / 100, 400);

  SilhouetteMask disc(300, 300, 4), grown_disc(300, 300, 4);
  fill_disc(disc, 150.2, 149.7, 100);
  fill_disc(grown_disc, 150.2, 149.7, 100.5);
  // Sampling noise (a few px^2 of 629 px^2 of difference, see the disc's area above) and the edge
  // length's 1 %.
  EXPECT_NEAR(silhouette_edge_error(disc, grown_disc).error_px, 0.5 * (1 + 0.5 / 200), 0.01);
}

TEST(SilhouetteRaster, EmptyReferenceHasNoErrorToMeasure) {
  SilhouetteMask empty(50, 50, 4), other(50, 50, 4);
  fill_rectangle(other, 10, 10, 20, 20);
  EXPECT_TRUE(std::isnan(silhouette_edge_error(empty, other).error_px));
  EXPECT_THROW(SilhouetteMask(0, 10, 4), std::invalid_argument);
  EXPECT_THROW(SilhouetteMask(10, 10, 0), std::invalid_argument);
  EXPECT_THROW(SilhouetteMask(16384, 16384, 4), std::invalid_argument);  // 2^32 samples: over 2^31
  EXPECT_THROW(SilhouetteMask(10, 10, 4).symmetric_difference_px(SilhouetteMask(10, 10, 2)), std::invalid_argument);
}

// A cube seen face-on through a pinhole: its silhouette is the square the closed form projects.
TEST(SilhouetteRaster, CubeFaceOnProjectsToItsSquare) {
  const CameraModel camera = CameraModel::pinhole(500, 500, 319.5, 239.5, 640, 480);
  const Mesh cube = make_cube_mesh(0.06, 8);  // centre (0, 0, 0.03)
  const double distance = 0.5;
  const SE3 T_cam_mesh = look_at({0, 0, 0.03 + distance}, {0, 0, 0.03});  // from above: the face at z = 0.06
  SilhouetteMask mask(640, 480, 4);
  EXPECT_EQ(draw_mesh_silhouette(cube, camera, T_cam_mesh, mask), 0u);
  const double side_px = 500 * 0.06 / (distance - 0.03);  // the near face is the outline
  EXPECT_NEAR(mask.area_px(), side_px * side_px, 4 * side_px * 0.25);
  EXPECT_NEAR(silhouette_edge_length_px(mask), 4 * side_px, kSquareCornerCuts);
}

TEST(SilhouetteViews, TwentySixViewsLookAtTheCentreFromTheDistance) {
  const Bounds box{{-1, -2, 0}, {1, 2, 3}};
  const std::vector<SilhouetteView> views = cube_views_around(box, 10);
  ASSERT_EQ(views.size(), 26u);
  const Vec3 centre{0, 0, 1.5};
  for (const SilhouetteView& view : views) {
    const Vec3 in_camera = view.T_cam_mesh * centre;
    EXPECT_NEAR(in_camera[0], 0, 1e-12) << view.name;
    EXPECT_NEAR(in_camera[1], 0, 1e-12) << view.name;
    EXPECT_NEAR(in_camera[2], 10, 1e-12) << view.name;
    const double det = dot(cross(view.T_cam_mesh.rotation()[0], view.T_cam_mesh.rotation()[1]), view.T_cam_mesh.rotation()[2]);
    EXPECT_NEAR(det, 1, 1e-12) << view.name;
  }
  EXPECT_EQ(views.front().name, "-x-y-z");
  EXPECT_EQ(views.back().name, "+x+y+z");
  // The image's up is the mesh's +z: a point above the centre is above the image centre (y down).
  const SE3 side = look_at({10, 0, 0}, {0, 0, 0});
  EXPECT_LT((side * Vec3{0, 0, 1})[1], 0);
  // Half the smaller side: 4 f r / min(w, h).
  const CameraModel camera = default_silhouette_camera();
  EXPECT_NEAR(camera.fx(), 320 / std::tan(std::numbers::pi / 6), 1e-9);
  EXPECT_NEAR(*default_view_distance_m(box, camera), 4 * camera.fx() * bounding_radius_m(box) / 480, 1e-12);
}

}  // namespace
}  // namespace arpipe
