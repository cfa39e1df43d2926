// A large proxy mesh cut into spatially compact clusters of triangles, each a part with its own
// bounds, so that the occluder pass draws only the clusters whose box reaches into the frame's
// footprint: a software rasteriser spends about a microsecond per triangle submitted, scissored
// or not, and a proxy near the camera mostly lies outside the few objects' footprint.
#pragma once

#include <cstddef>
#include <vector>

#include "core/scene/mesh.h"

namespace arpipe {

struct ClusteredMesh {
  Mesh mesh;                    // the same triangles, reordered; one part per cluster
  std::vector<Bounds> bounds;   // per part, in the mesh's frame
};

// Triangles ordered along a Morton (Z-order) curve of their centroids within the mesh's bounds,
// cut every triangles_per_cluster. A mesh of at most 2 clusters' triangles comes back whole
// (one part, no bounds: not worth culling).
ClusteredMesh cluster_for_culling(const Mesh& mesh, size_t triangles_per_cluster = 256);

}  // namespace arpipe
