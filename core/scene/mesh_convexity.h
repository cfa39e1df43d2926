// Whether a mesh bounds a convex solid: then no part of it can shadow another part of it that faces
// the light, so its shadow lookups need only look for other casters (render/shadow/unshadowed_objects.h).
#pragma once

#include "core/scene/mesh.h"

namespace arpipe {

// True when the mesh, welded by position, is closed (every edge paired with one wound the other
// way) and convex: every vertex lies on or behind every triangle's plane, within 1e-6 of the
// mesh's diagonal. False for a mesh that is not one (no triangles, bad indices), for degenerate
// input and, without checking, for meshes of more than kMaxConvexityWork vertex-plane tests.
bool is_closed_convex(const Mesh& mesh);
inline constexpr double kMaxConvexityWork = 5e7;

}  // namespace arpipe
