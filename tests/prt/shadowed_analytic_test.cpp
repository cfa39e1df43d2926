// Shadowed transfer where the visibility has a closed form: T_0 = y_0 * (1/pi) * (the cosine-
// weighted solid angle left) = y_0 * (1 - F_blocked) = y_0 * F_open, F a point-to-polygon view
// factor: a floor at the foot of a tall wall, and the floor of an open box seen through its top.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/sh/sh_basis.h"
#include "render/prt/prt_bake.h"
#include "render/prt/prt_test_meshes.h"
#include "tests/prt/prt_test_support.h"

namespace arpipe {
namespace {

constexpr double kY0 = 0.28209479177387814;  // 1 / (2 sqrt(pi))

// Tolerance of T_0 against the closed form at N = 128 (16384 directions). The error of jittered
// stratified sampling comes from the cells the visibility edge crosses: each is one independent
// term of size at most w * f_max with w = 4 pi / N^2 and f_max = y_0 / pi (the integrand of T_0:
// y_0 cos / pi), so with B crossed cells sigma <= w f_max sqrt(B) / 2. An edge that circles the
// pole or runs across the square crosses B <= 2N cells: sigma <= 5.5e-4, and 4 sigma = 2.2e-3.
// Cells away from the edge add far less (the smooth cosine: RMS 5e-5, see the unshadowed test).
// Measured over 40 seeds at N = 128: RMS 2.1e-4 (box centre) and 2.6e-4 (wall), mean below 3e-5
// (no bias from the ray offset), worst 6.5e-4.
constexpr int kSamples = 128;
constexpr double kTolerance = 2.2e-3;

PrtTransfer bake_shadowed(const Mesh& mesh) {
  PrtBakeSettings settings;
  settings.kind = TransferKind::Shadowed;
  settings.bands = 3;
  settings.samples_per_axis = kSamples;
  return bake_prt(mesh, settings);
}

TEST(PrtShadowedAnalytic, FloorAtTheFootOfAWall) {
  const double half_width = 2.0, depth = 1.0, height = 4.0;
  const Mesh mesh = make_floor_with_wall(half_width, depth, height, 4);
  const PrtTransfer transfer = bake_shadowed(mesh);
  const double offset = 1e-4 * prt_test::mesh_diagonal(mesh);  // the bake's default ray offset
  double max_error = 0;
  // Floor vertices a grid step from the wall's foot, further out, and on the floor's edge (not on
  // the foot itself, y = 0, where the ray would start in the wall's own plane).
  for (const Vec3 where : {Vec3{0, 0.25, 0}, Vec3{0, 0.5, 0}, Vec3{1.0, 0.25, 0}, Vec3{-1.0, 1.0, 0}, Vec3{0, 1.0, 0},
                           Vec3{2.0, 0.5, 0}}) {
    const size_t v = prt_test::find_vertex(mesh, where, {0, 0, 1});
    const Vec3 p = prt_test::vertex_position(mesh, v) + Vec3{0, 0, offset};
    ASSERT_LT(norm(prt_test::vertex_position(mesh, v) - where), 1e-6);
    // The part of the wall above the ray origin's horizon blocks; the floor is below it.
    const double blocked = prt_test::polygon_view_factor(
        p, {0, 0, 1},
        {{-half_width, 0, offset}, {half_width, 0, offset}, {half_width, 0, height}, {-half_width, 0, height}});
    const double want = kY0 * (1 - blocked);
    const double got = transfer.at(v)[0];
    max_error = std::max(max_error, std::abs(got - want));
    EXPECT_NEAR(got, want, kTolerance) << "floor vertex at (" << where[0] << ", " << where[1] << "), F_wall "
                                       << blocked;
  }
  std::printf("floor and wall, N = %d: max |T_0 - y_0 (1 - F_wall)| = %.3g\n", kSamples, max_error);
}

TEST(PrtShadowedAnalytic, CentreOfAnOpenBoxSeesTheSkyThroughItsOpening) {
  const double side = 1.0, height = 0.5;
  const Mesh mesh = make_open_box(side, height, 2);
  const PrtTransfer transfer = bake_shadowed(mesh);
  const double offset = 1e-4 * prt_test::mesh_diagonal(mesh);
  const size_t v = prt_test::find_vertex(mesh, {0, 0, 0}, {0, 0, 1});
  ASSERT_LT(norm(prt_test::vertex_position(mesh, v)), 1e-6);
  // Four quarters of the opening, each a (side/2)^2 rectangle with a corner above the point.
  const double open = 4 * prt_test::parallel_rectangle_corner_view_factor(side / 2, side / 2, height - offset);
  // The same from Lambert's contour formula (a check of the test's own closed forms).
  const double h = side / 2;
  EXPECT_NEAR(open,
              prt_test::polygon_view_factor({0, 0, offset}, {0, 0, 1},
                                            {{-h, -h, height}, {h, -h, height}, {h, h, height}, {-h, h, height}}),
              1e-12);
  const double got = transfer.at(v)[0];
  std::printf("open box centre, N = %d: F_open = %.5f, T_0 = %.5f, want %.5f, error %.3g\n", kSamples, open, got,
              kY0 * open, got - kY0 * open);
  EXPECT_NEAR(got, kY0 * open, kTolerance);
  // By symmetry the linear and the tilted quadratic terms vanish; T_2 (the z lobe) is positive.
  const auto t = transfer.at(v);
  EXPECT_GT(t[sh_index(1, 0)], 0);
  for (int i : {sh_index(1, -1), sh_index(1, 1), sh_index(2, -2), sh_index(2, -1), sh_index(2, 1)})
    EXPECT_NEAR(t[size_t(i)], 0, kTolerance) << "coefficient " << i;
}

// Vertices on the box's seams: a floor vertex where a wall stands on its edge (and one in the
// corner, where two do), and a wall vertex standing on the floor. Their offset ray origins would
// lie in the other surface's plane; the walls (or the floor) must still block: the sky is seen
// only through the opening, T_0 = y_0 F_opening from the vertex with its own normal.
TEST(PrtShadowedAnalytic, SeamVerticesOfAnOpenBoxAreShadowedByTheWallsTheyTouch) {
  const double side = 1.0, height = 0.5, h = side / 2;
  const Mesh mesh = make_open_box(side, height, 2);
  const PrtTransfer transfer = bake_shadowed(mesh);
  const double offset = 1e-4 * prt_test::mesh_diagonal(mesh);
  const std::vector<Vec3> opening{{-h, -h, height}, {h, -h, height}, {h, h, height}, {-h, h, height}};
  struct Case {
    Vec3 where, normal;
  };
  for (const Case& c : {Case{{h, 0, 0}, {0, 0, 1}}, Case{{h, h, 0}, {0, 0, 1}}, Case{{-h, 0, 0}, {1, 0, 0}}}) {
    const size_t v = prt_test::find_vertex(mesh, c.where, c.normal);
    ASSERT_LT(norm(prt_test::vertex_position(mesh, v) - c.where), 1e-6);
    const double open = prt_test::polygon_view_factor(c.where + offset * c.normal, c.normal, opening);
    const double got = transfer.at(v)[0];
    std::printf("seam vertex (%g, %g, %g): T_0 = %.5f, want y_0 F = %.5f, error %.3g\n", c.where[0], c.where[1],
                c.where[2], got, kY0 * open, got - kY0 * open);
    EXPECT_NEAR(got, kY0 * open, kTolerance) << "vertex at (" << c.where[0] << ", " << c.where[1] << ", "
                                             << c.where[2] << ")";
  }
}

}  // namespace
}  // namespace arpipe
