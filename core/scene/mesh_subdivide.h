// A mesh cut into triangles no longer than a given edge: what a projection that is not a plain
// perspective (a stereo panorama's eye, core/geometry/ods_projection.h) needs, since the
// rasteriser joins the projected vertices with straight lines.
#pragma once

#include <cstddef>
#include <vector>

#include "core/scene/mesh.h"

namespace arpipe {

// Each triangle's longest edge is cut at its midpoint until no edge is longer than max_edge_m, so
// an edge two triangles share is cut the same way in both (no cracks) and parts keep their order.
// Normals are interpolated and renormalised. When that would make more than max_triangles, the
// edge allowed grows until it does not; `used_edge_m`, when given, receives the edge used.
Mesh subdivided(const Mesh& mesh, double max_edge_m, size_t max_triangles = 1'000'000, double* used_edge_m = nullptr);

// The same, carrying values_per_vertex floats a vertex along (a PRT transfer): each new vertex gets
// the mean of its edge's ends, the value the rasteriser interpolates there, so the cut mesh shades
// exactly as the whole one. vertex_values holds mesh's vertices' values and receives the cut's.
Mesh subdivided(const Mesh& mesh, std::vector<float>& vertex_values, size_t values_per_vertex, double max_edge_m,
                size_t max_triangles = 1'000'000, double* used_edge_m = nullptr);

}  // namespace arpipe
