// The PRT bake (seed 002, section 2.6): per-vertex diffuse transfer vectors of one mesh, by Monte
// Carlo over the seed's jittered sphere sampler, with Embree shadow rays and an optional bounce.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>

#include "core/scene/mesh.h"
#include "render/prt/prt_transfer.h"

namespace arpipe {

struct PrtBakeStats {
  uint64_t rays = 0;      // shadow rays plus (interreflected) closest-hit rays
  double seconds = 0;     // wall-clock time of the whole bake
  int threads = 0;        // workers used
};

// T_i(v) (prt_transfer.h) by stratified_sphere_samples(samples_per_axis, bands, seed): every vertex
// uses the same N^2 directions w_j of weight 4 pi / N^2, and
//   Unshadowed:     T_i = (1/pi) sum_j w y_i(w_j) max(0, n.w_j)              (no rays)
//   Shadowed:       the same over the w_j with n.w_j > 0 whose ray from the vertex, offset by
//                   ray_offset * (bounding-box diagonal) along n, hits nothing. The origin also
//                   moves up to that distance tangentially into the vertex's own triangles: a
//                   vertex on a seam (a floor vertex at the foot of a wall) would otherwise start
//                   its rays in the wall's plane, and Embree lets a ray that starts on a triangle
//                   pass through it. On a convex mesh with flat faces no ray hits anything still.
//   Interreflected: Sloan, Kautz and Snyder 2002 with one bounce, an extension beyond the seed:
//                   T_i = T_shadowed,i + (1/pi) sum over the blocked w_j of
//                         rho_hit * T_shadowed,i(hit) * max(0, n.w_j) * w,
//                   T_shadowed at the hit interpolated from the hit triangle's vertices by
//                   barycentrics, rho_hit the luminance (0.2126, 0.7152, 0.0722) of the hit part's
//                   base colour (a grey bounce, so the transfer stays one scalar vector; triangles
//                   in no part count as white). A hit on a triangle's back face adds nothing.
// Rays: the n.w_j > 0 samples of one vertex go to Embree together as a coherent ray stream
// (rtcOccluded1M, and rtcIntersect1M for the bounce pass, which casts closest-hit rays for the
// whole hemisphere again after the shadowed pass): 1.7-1.9x the rays per second of one
// rtcOccluded1 / rtcIntersect1 call per ray on `arpipe bench prt`'s box (2 cores).
// n is the mesh's vertex normal. Runs on settings.threads workers (0: hardware_concurrency, at least 1);
// each vertex is summed in sample order by one worker, so the result has the same bits for any
// thread count. `progress(done, total)` is called on the calling thread only, after each chunk of
// vertices (total = vertices, twice that for Interreflected, which makes two passes).
// Throws AssetError for a malformed mesh (normal count, non-finite values, index out of range),
// std::invalid_argument for bad settings (bands outside [1, kMaxShBands], samples < 1, negative or
// non-finite offset). An empty mesh gives an empty transfer.
PrtTransfer bake_prt(const Mesh& mesh, const PrtBakeSettings& settings,
                     const std::function<void(size_t done, size_t total)>& progress = {},
                     PrtBakeStats* stats = nullptr);

// The checks bake_prt makes before it starts (AssetError naming the mesh's file, Mesh::source, when
// known, the vertex or index and what is wrong).
void validate_prt_mesh(const Mesh& mesh);

}  // namespace arpipe
