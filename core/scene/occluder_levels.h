// Coarser levels of detail of a proxy's mesh for drawing it as an occluder (depth only), each with
// how far its surface may stray from the full mesh. An occluder is only its silhouette: a level
// whose error, seen from the camera, is well under a pixel hides exactly the same pixels at a
// fraction of the triangles (a software rasteriser pays about a microsecond per triangle, and a
// finely tessellated cylinder's slivers cost far more than their pixels).
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "core/scene/mesh.h"

namespace arpipe {

struct OccluderLevel {
  std::shared_ptr<const Mesh> mesh;
  // How far the level's surface may lie from the full mesh's (meshoptimizer's result error times
  // its scale), in the mesh's units (unscaled).
  double error = 0;
};

// Levels from finest to coarsest, each with at most half the triangles of the one before it (the
// full mesh first, not included). Made with meshopt_simplify at error bounds from 0.01 % to 3 %
// of the mesh's size. None for a mesh of fewer than kMinOccluderLevelTriangles
// triangles, or one meshoptimizer cannot weld (the full mesh serves). No GL: runs off the
// processing thread.
inline constexpr size_t kMinOccluderLevelTriangles = 64;
std::vector<OccluderLevel> make_occluder_levels(const Mesh& mesh);

// The index of the coarsest level whose error (errors_m: each level's, scaled, finest first),
// projected at depth_m by focal_px, is at most tolerance_px; -1 for the full mesh (none fits,
// tolerance 0, or a depth at or behind the eye).
int coarsest_occluder_level(std::span<const double> errors_m, double focal_px, double depth_m, double tolerance_px);

}  // namespace arpipe
