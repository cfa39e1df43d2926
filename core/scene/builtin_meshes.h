// The procedural meshes a scene can name without a file ("builtin:cube", "builtin:pyramid",
// "builtin:sphere", "builtin:cup", "builtin:box", "builtin:cylinder", "builtin:plane"):
// base on z = 0, centred on the object origin in x and y, about 6 cm across.
#pragma once

#include <optional>
#include <string_view>

#include "core/scene/mesh.h"

namespace arpipe {

// Faces are split into a grid of subdivisions x subdivisions because lens distortion is applied
// per vertex: between vertices the rasteriser draws straight lines, so long edges need vertices.
Mesh make_cube_mesh(double edge_m = 0.06, int subdivisions = 8);
Mesh make_pyramid_mesh(double base_m = 0.06, double height_m = 0.06, int subdivisions = 8);
// Resting on z = 0: centre at (0, 0, radius).
Mesh make_sphere_mesh(double radius_m = 0.03, int rings = 24);
// A concave solid: a box of outer_m x outer_m x height_m with a square pit inner_m across and
// depth_m deep open at the top, flat faces (the walls shade each other: PRT's test model).
Mesh make_cup_mesh(double outer_m = 0.06, double inner_m = 0.04, double height_m = 0.06, double depth_m = 0.045,
                   int subdivisions = 8);
// A square on z = 0 facing +z (the shadow catcher's ground patch).
Mesh make_plane_mesh(double edge_m = 1.0, int subdivisions = 8);
// A box of size x, y, z (metres), base on z = 0, flat faces: a proxy for a real carton or table.
Mesh make_box_mesh(const Vec3& size_m = {0.06, 0.06, 0.06}, int subdivisions = 8);
// A rectangle of size x, y on z = 0 facing +z.
Mesh make_rectangle_mesh(double x_m = 0.06, double y_m = 0.06, int subdivisions = 8);
// An upright cylinder, base on z = 0: diameters size x and y (an elliptic section when they
// differ), height size z; smooth side normals, flat caps; `segments` around (at least 3).
Mesh make_cylinder_mesh(const Vec3& size_m = {0.06, 0.06, 0.06}, int segments = 48, int subdivisions = 8);

// How a scene names a builtin mesh instead of a file: "builtin:cube", "builtin:pyramid".
inline constexpr std::string_view kBuiltinMeshPrefix = "builtin:";
inline constexpr std::string_view kBuiltinMeshNames =
    "\"builtin:cube\", \"builtin:pyramid\", \"builtin:sphere\", \"builtin:cup\", \"builtin:box\", "
    "\"builtin:cylinder\", \"builtin:plane\"";
bool is_builtin_mesh_source(std::string_view source);
// The builtin mesh a source names, at its default size; nullopt for an unknown builtin name.
std::optional<Mesh> make_builtin_mesh(std::string_view source);
// The same, with "builtin:box", "builtin:cylinder" and "builtin:plane" made at size_m (x, y, z;
// the plane ignores z), and their faces, "builtin:cube"'s and "builtin:pyramid"'s split into
// subdivisions x subdivisions (1: a box of 12 triangles, where no lens distortion is applied per
// vertex); the sphere and the cup ignore both.
std::optional<Mesh> make_builtin_mesh(std::string_view source, const Vec3& size_m, int subdivisions = 8);
// Whether a builtin takes its size from size_m.
bool builtin_mesh_is_sized(std::string_view source);

}  // namespace arpipe
