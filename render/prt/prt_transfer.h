// Per-vertex diffuse transfer vectors for precomputed radiance transfer (seed 002, Sloan-Kautz-Snyder
// 2002): what the bake produces, the cache stores and the PRT shading multiplies with the lighting.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace arpipe {

// Convention. A surface of albedo rho at vertex v, lit by distant radiance whose SH coefficients
// are L_i in the OBJECT frame (real SH, core/sh/sh_basis.h), leaves with radiance
//   L_out(v) = rho * sum_i L_i T_i(v),   T_i(v) = (1/pi) * integral y_i(w) V(v, w) max(0, n.w) dw.
// The Lambertian 1/pi (rho/pi is the BRDF) is folded into T, the albedo is not: it is applied at run
// time per mesh part, so one scalar vector per vertex serves every colour channel. Unshadowed
// (V = 1): T_i = A_l / pi * y_i(n) with A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4.
enum class TransferKind {
  Unshadowed,      // V = 1 (seed 002, Eq. 4.8)
  Shadowed,        // V = 0 where a ray from the vertex hits the mesh (seed 002, Eq. 4.9)
  Interreflected,  // shadowed + one diffuse bounce (an extension beyond the seed, after SKS02; prt_bake.h)
};

// "unshadowed", "shadowed", "interreflected"; nullopt for anything else.
std::optional<TransferKind> parse_transfer_kind(std::string_view name);
std::string_view transfer_kind_name(TransferKind kind);

struct PrtBakeSettings {
  TransferKind kind = TransferKind::Shadowed;
  int bands = 3;               // SH bands: bands^2 coefficients per vertex
  int samples_per_axis = 32;   // the seed's jittered N x N sphere sampler (N^2 directions)
  uint64_t seed = 1;           // the sampler's jitter
  // Self-intersection offset, times the mesh's bounding-box diagonal: shadow rays start this far
  // along the vertex normal. A deviation from the seed, whose rays start at the vertex with t >= 0
  // and so hit the vertex's own triangles (seed 002, section 2.6). The origin also moves as far
  // tangentially into the vertex's own triangles, for vertices on seams (prt_bake.h).
  double ray_offset = 1e-4;
  // Worker threads; 0: std::thread::hardware_concurrency(). Not part of the cache key: the result
  // has the same bits for any count.
  int threads = 0;
};

struct PrtTransfer {
  int bands = 0;
  TransferKind kind = TransferKind::Shadowed;
  int samples_per_axis = 0;         // the bake's sampler N (N^2 directions), recorded in the cache
  std::vector<float> coefficients;  // vertex-major, bands^2 per vertex

  size_t vertex_count() const;
  std::span<const float> at(size_t vertex) const;  // bands^2 values; vertex < vertex_count()
};

}  // namespace arpipe
