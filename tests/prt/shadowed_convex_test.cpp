// On a convex mesh with flat faces no ray from a vertex meets the mesh again, so the shadowed (and
// interreflected) transfer must equal the unshadowed one: the offset rays of the builtin cube.
#include <gtest/gtest.h>

#include "core/scene/builtin_meshes.h"
#include "render/prt/prt_bake.h"

namespace arpipe {
namespace {

PrtTransfer bake_cube(TransferKind kind, PrtBakeStats* stats = nullptr) {
  PrtBakeSettings settings;
  settings.kind = kind;
  settings.samples_per_axis = 16;
  return bake_prt(make_cube_mesh(0.06, 4), settings, {}, stats);
}

// Every sample is summed in the same order whether or not rays are cast, so when no ray is
// blocked the bits are the same: compared exactly.
TEST(PrtShadowedConvex, CubeShadowedEqualsUnshadowedExactly) {
  const PrtTransfer unshadowed = bake_cube(TransferKind::Unshadowed);
  PrtBakeStats stats;
  const PrtTransfer shadowed = bake_cube(TransferKind::Shadowed, &stats);
  EXPECT_GT(stats.rays, 0u);
  ASSERT_EQ(shadowed.coefficients.size(), unshadowed.coefficients.size());
  EXPECT_EQ(shadowed.coefficients, unshadowed.coefficients);
}

// Nothing is hit, so there is no bounce either. The bounce adds a sum of zero terms in double
// before the final rounding to float: exactly equal.
TEST(PrtShadowedConvex, CubeInterreflectedEqualsShadowed) {
  const PrtTransfer shadowed = bake_cube(TransferKind::Shadowed);
  const PrtTransfer interreflected = bake_cube(TransferKind::Interreflected);
  EXPECT_EQ(interreflected.coefficients, shadowed.coefficients);
}

}  // namespace
}  // namespace arpipe
