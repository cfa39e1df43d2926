// Concave meshes whose shadowed transfer has a closed form, for the PRT tests and `arpipe bench prt`:
// an open box (floor and four walls, open at the top) and a floor at the foot of one wall.
#pragma once

#include "core/scene/mesh.h"

namespace arpipe {

// A square floor of edge `side` on z = 0 centred on the origin, facing +z, and four walls of
// `height` on its edges facing inwards; open at the top. Every face is a subdivisions x
// subdivisions grid with its own vertices (flat normals), counter-clockwise seen from inside.
// From a floor point the sky is seen only through the opening, so its visibility is the view
// factor to a square parallel to the floor. One white part.
Mesh make_open_box(double side = 1.0, double height = 0.5, int subdivisions = 8);

// A floor x in [-half_width, half_width], y in [0, depth] on z = 0 facing +z, and a wall on its
// edge y = 0, x in [-half_width, half_width], z in [0, height], facing +y: from a floor point the
// wall hides a rectangle perpendicular to the floor. One white part.
Mesh make_floor_with_wall(double half_width = 2.0, double depth = 1.0, double height = 4.0, int subdivisions = 8);

}  // namespace arpipe
