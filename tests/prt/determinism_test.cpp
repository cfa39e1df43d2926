// The bake's result does not depend on how many threads share the work: the same bits for 1, 2
// and 5 workers (5 does not divide the chunks evenly), for every kind.
#include <gtest/gtest.h>

#include <thread>

#include "render/prt/prt_bake.h"
#include "render/prt/prt_test_meshes.h"

namespace arpipe {
namespace {

TEST(PrtDeterminism, SameBitsForAnyThreadCount) {
  const Mesh box = make_open_box(1.0, 0.5, 6);  // 245 vertices: several 64-vertex chunks
  for (TransferKind kind : {TransferKind::Unshadowed, TransferKind::Shadowed, TransferKind::Interreflected}) {
    PrtBakeSettings settings;
    settings.kind = kind;
    settings.samples_per_axis = 12;
    settings.threads = 1;
    const PrtTransfer one = bake_prt(box, settings);
    for (int threads : {2, 5}) {
      settings.threads = threads;
      EXPECT_EQ(bake_prt(box, settings).coefficients, one.coefficients)
          << transfer_kind_name(kind) << " with " << threads << " threads";
    }
  }
}

// Progress comes from the calling thread only, increases, and ends at the total (twice the
// vertices for the interreflected bake's two passes).
TEST(PrtDeterminism, ProgressReachesTheTotalOnTheCallingThread) {
  const Mesh box = make_open_box(1.0, 0.5, 6);
  PrtBakeSettings settings;
  settings.kind = TransferKind::Interreflected;
  settings.samples_per_axis = 4;
  settings.threads = 2;
  const auto caller = std::this_thread::get_id();
  size_t last = 0, calls = 0, total_seen = 0;
  bool same_thread = true;
  bake_prt(box, settings, [&](size_t done, size_t total) {
    same_thread = same_thread && std::this_thread::get_id() == caller;
    EXPECT_GT(done, last);
    last = done;
    total_seen = total;
    ++calls;
  });
  EXPECT_TRUE(same_thread);
  EXPECT_EQ(total_seen, 2 * box.vertex_count());
  EXPECT_EQ(last, total_seen);
  EXPECT_GE(calls, 2u);
}

TEST(PrtDeterminism, EmptyMeshBakesToAnEmptyTransfer) {
  const PrtTransfer t = bake_prt(Mesh{}, PrtBakeSettings{});
  EXPECT_EQ(t.vertex_count(), 0u);
  EXPECT_TRUE(t.coefficients.empty());
  EXPECT_EQ(t.bands, 3);
}

}  // namespace
}  // namespace arpipe
