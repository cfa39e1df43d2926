// A mesh cut into triangles no longer than a given edge: what a projection that is not a plain
// perspective (a stereo panorama's eye, core/geometry/ods_projection.h) needs, since the
// rasteriser joins the projected vertices with straight lines.
#pragma once

#include <cstddef>

#include "core/scene/mesh.h"

namespace arpipe {

// Each triangle's longest edge is cut at its midpoint until no edge is longer than max_edge_m, so
// an edge two triangles share is cut the same way in both (no cracks) and parts keep their order.
// Normals are interpolated and renormalised. When that would make more than max_triangles, the
// edge allowed grows until it does not; `used_edge_m`, when given, receives the edge used.
Mesh subdivided(const Mesh& mesh, double max_edge_m, size_t max_triangles = 1'000'000, double* used_edge_m = nullptr);

}  // namespace arpipe
