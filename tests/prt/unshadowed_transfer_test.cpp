// Unshadowed transfer against its closed form T_i = A_l / pi * y_i(n) (Ramamoorthi and Hanrahan's
// clamped-cosine convolution), at the vertices of a sphere, whose normals point every way.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/sh/sh_basis.h"
#include "core/scene/builtin_meshes.h"
#include "render/prt/prt_bake.h"
#include "tests/prt/prt_test_support.h"

namespace arpipe {
namespace {

TEST(PrtUnshadowed, EqualsTheClampedCosineConvolution) {
  const Mesh sphere = make_sphere_mesh(0.03, 8);
  PrtBakeSettings settings;
  settings.kind = TransferKind::Unshadowed;
  settings.bands = 3;
  settings.samples_per_axis = 128;  // no rays: 16384 directions cost little
  const PrtTransfer transfer = bake_prt(sphere, settings);
  ASSERT_EQ(transfer.vertex_count(), sphere.vertex_count());
  ASSERT_EQ(transfer.bands, 3);
  double max_error = 0;
  for (size_t v = 0; v < sphere.vertex_count(); ++v) {
    const std::vector<double> y = sh_basis(3, normalized(prt_test::vertex_normal(sphere, v)));
    for (int l = 0; l < 3; ++l)
      for (int m = -l; m <= l; ++m) {
        const int i = sh_index(l, m);
        const double want = prt_test::cosine_lobe_factor(l) / std::numbers::pi * y[size_t(i)];
        const double error = std::abs(transfer.at(v)[size_t(i)] - want);
        max_error = std::max(max_error, error);
        // The jittered sampler's error for y_i times the clamped cosine falls as N^-2 (measured
        // on this sphere over all vertices and coefficients: RMS 1.3e-3 at N = 32, 3.4e-4 at 64,
        // 8.8e-5 at 128 and 3.7e-5 at 200, where T_0's RMS of 1.9e-5 agrees with the seed
        // author's 5e-5 for the cosine lobe; the worst of 20 seeds at N = 128 was 3.8e-4).
        // 6e-4 is 7 RMS at N = 128, and still catches a wrong factor (A_2 / pi = 1/4 instead of
        // 1/3 moves T by 0.08 y, up to 0.05).
        EXPECT_NEAR(transfer.at(v)[size_t(i)], want, 6e-4) << "vertex " << v << " coefficient " << i;
      }
  }
  std::printf("unshadowed, N = 128: max |T - A_l/pi y(n)| = %.3g\n", max_error);
}

}  // namespace
}  // namespace arpipe
