// The procedural meshes a scene can name without a file ("builtin:cube", "builtin:pyramid"):
// base on z = 0, centred on the object origin in x and y, about 6 cm across.
#pragma once

#include "core/scene/mesh.h"

namespace arpipe {

// Faces are split into a grid of subdivisions x subdivisions because lens distortion is applied
// per vertex: between vertices the rasteriser draws straight lines, so long edges need vertices.
Mesh make_cube_mesh(double edge_m = 0.06, int subdivisions = 8);
Mesh make_pyramid_mesh(double base_m = 0.06, double height_m = 0.06, int subdivisions = 8);

}  // namespace arpipe
