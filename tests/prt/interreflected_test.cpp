// The one-bounce interreflected transfer (the SKS02 extension): light reflected by the box's walls
// adds to the floor's shadowed transfer, never removes; a black box reflects nothing.
#include <gtest/gtest.h>

#include <cstdio>

#include "render/prt/prt_bake.h"
#include "render/prt/prt_test_meshes.h"
#include "tests/prt/prt_test_support.h"

namespace arpipe {
namespace {

PrtTransfer bake_box(const Mesh& mesh, TransferKind kind) {
  PrtBakeSettings settings;
  settings.kind = kind;
  settings.samples_per_axis = 32;
  return bake_prt(mesh, settings);
}

TEST(PrtInterreflected, AddsTheWallsBounceAtAConcaveVertex) {
  const Mesh box = make_open_box(1.0, 0.5, 4);
  const PrtTransfer shadowed = bake_box(box, TransferKind::Shadowed);
  const PrtTransfer interreflected = bake_box(box, TransferKind::Interreflected);
  const size_t centre = prt_test::find_vertex(box, {0, 0, 0}, {0, 0, 1});
  const size_t corner = prt_test::find_vertex(box, {0.5, 0.5, 0}, {0, 0, 1});
  for (size_t v : {centre, corner}) {
    const double s = shadowed.at(v)[0], r = interreflected.at(v)[0];
    std::printf("vertex %zu: T_0 shadowed %.5f, interreflected %.5f (+%.1f%%)\n", v, s, r, 100 * (r - s) / s);
    // The walls see the sky through the opening, so their shadowed T_0 is positive and the floor
    // sees them: the bounce is a sum of positive terms (white walls, front faces), strictly > 0.
    EXPECT_GT(r, s);
    // An upper bound: the bounce cannot exceed the blocked cosine-weighted fraction (1 - F) times
    // the brightest wall T_0 (at most y_0), i.e. y_0 - shadowed T_0 (white walls).
    // 1e-3: the sampler's error of the cosine integral at N = 32 (both sides are sample sums).
    EXPECT_LE(r - s, 0.28209479177387814 - s + 1e-3);
  }
  // No vertex loses light: the bounce adds non-negative terms to T_0 (every shadowed T_0 >= 0).
  for (size_t v = 0; v < box.vertex_count(); ++v) EXPECT_GE(interreflected.at(v)[0], shadowed.at(v)[0]) << v;
}

// A black mesh (luminance 0) reflects nothing: interreflected = shadowed, bit for bit (the bounce
// sum is exactly zero before the float rounding).
TEST(PrtInterreflected, BlackWallsBounceNothing) {
  Mesh box = make_open_box(1.0, 0.5, 2);
  box.set_base_color({0, 0, 0, 1});
  EXPECT_EQ(bake_box(box, TransferKind::Interreflected).coefficients,
            bake_box(box, TransferKind::Shadowed).coefficients);
}

// Half the albedo, half the bounce: the bounce is linear in rho_hit (luminance of the base colour).
TEST(PrtInterreflected, BounceIsLinearInTheLuminanceOfTheHitPart) {
  Mesh white = make_open_box(1.0, 0.5, 2);
  Mesh grey = white;
  grey.set_base_color({0.5, 0.5, 0.5, 1});
  const PrtTransfer shadowed = bake_box(white, TransferKind::Shadowed);
  const PrtTransfer a = bake_box(white, TransferKind::Interreflected);
  const PrtTransfer b = bake_box(grey, TransferKind::Interreflected);
  for (size_t i = 0; i < a.coefficients.size(); ++i)
    // Float rounding of the stored vectors only: 1e-6 against coefficients below 0.3.
    EXPECT_NEAR(b.coefficients[i] - shadowed.coefficients[i], 0.5 * (a.coefficients[i] - shadowed.coefficients[i]),
                1e-6)
        << i;
}

}  // namespace
}  // namespace arpipe
