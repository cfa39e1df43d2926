// The procedural meshes a scene can name without a file ("builtin:cube", "builtin:pyramid",
// "builtin:sphere", "builtin:cup"):
// base on z = 0, centred on the object origin in x and y, about 6 cm across.
#include "core/scene/builtin_meshes.h"

#include <algorithm>
#include <cmath>

namespace arpipe {
namespace {

class MeshBuilder {
 public:
  uint32_t add_vertex(const Vec3& position, const Vec3& normal) {
    for (int axis = 0; axis < 3; ++axis) {
      mesh_.positions.push_back(static_cast<float>(position[static_cast<size_t>(axis)]));
      mesh_.normals.push_back(static_cast<float>(normal[static_cast<size_t>(axis)]));
    }
    return static_cast<uint32_t>(mesh_.vertex_count() - 1);
  }
  size_t vertex_count() const { return mesh_.vertex_count(); }
  void add_triangle(uint32_t a, uint32_t b, uint32_t c) { mesh_.indices.insert(mesh_.indices.end(), {a, b, c}); }

  // Flat parallelogram origin + s*u + t*v, s and t in [0, 1]; u x v points outwards.
  void add_grid(const Vec3& origin, const Vec3& u, const Vec3& v, int n) {
    const Vec3 normal = normalized(cross(u, v));
    const uint32_t first = static_cast<uint32_t>(mesh_.vertex_count());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) add_vertex(origin + (double(i) / n) * u + (double(j) / n) * v, normal);
    auto at = [&](int i, int j) { return first + static_cast<uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        add_triangle(at(i, j), at(i + 1, j), at(i + 1, j + 1));
        add_triangle(at(i, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }

  // Flat triangle a, b, c (counter-clockwise seen from outside), split into n*n triangles.
  void add_subdivided_triangle(const Vec3& a, const Vec3& b, const Vec3& c, int n) {
    const Vec3 normal = normalized(cross(b - a, c - a));
    const uint32_t first = static_cast<uint32_t>(mesh_.vertex_count());
    // Row j holds the points a + i/n (b - a) + j/n (c - a) for i + j <= n.
    std::vector<uint32_t> row_start;
    for (int j = 0; j <= n; ++j) {
      row_start.push_back(static_cast<uint32_t>(mesh_.vertex_count()) - first);
      for (int i = 0; i + j <= n; ++i) add_vertex(a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a), normal);
    }
    auto at = [&](int i, int j) { return first + row_start[static_cast<size_t>(j)] + static_cast<uint32_t>(i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        add_triangle(at(i, j), at(i + 1, j), at(i, j + 1));
        if (i + j < n - 1) add_triangle(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }

  Mesh finish() {
    mesh_.parts = {MeshPart{0, static_cast<uint32_t>(mesh_.indices.size()), {1, 1, 1, 1}}};
    return std::move(mesh_);
  }

 private:
  Mesh mesh_;
};

}  // namespace

Mesh make_cube_mesh(double edge_m, int subdivisions) {
  const double s = edge_m, h = edge_m / 2;
  MeshBuilder builder;
  builder.add_grid({-h, -h, s}, {s, 0, 0}, {0, s, 0}, subdivisions);  // top, +z
  builder.add_grid({-h, -h, 0}, {0, s, 0}, {s, 0, 0}, subdivisions);  // bottom, -z
  builder.add_grid({h, -h, 0}, {0, s, 0}, {0, 0, s}, subdivisions);   // +x
  builder.add_grid({-h, -h, 0}, {0, 0, s}, {0, s, 0}, subdivisions);  // -x
  builder.add_grid({-h, h, 0}, {0, 0, s}, {s, 0, 0}, subdivisions);   // +y
  builder.add_grid({-h, -h, 0}, {s, 0, 0}, {0, 0, s}, subdivisions);  // -y
  return builder.finish();
}

Mesh make_pyramid_mesh(double base_m, double height_m, int subdivisions) {
  const double s = base_m, h = base_m / 2;
  const Vec3 apex{0, 0, height_m};
  MeshBuilder builder;
  builder.add_grid({-h, -h, 0}, {0, s, 0}, {s, 0, 0}, subdivisions);  // base, -z
  const Vec3 corners[4] = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};  // counter-clockwise about +z
  for (int side = 0; side < 4; ++side)
    builder.add_subdivided_triangle(corners[side], corners[(side + 1) % 4], apex, subdivisions);
  return builder.finish();
}

Mesh make_sphere_mesh(double radius_m, int rings) {
  // Latitude-longitude rings, 2 * rings segments around; smooth normals (the true sphere's).
  MeshBuilder builder;
  const int segments = 2 * rings;
  const double pi = 3.14159265358979323846;
  for (int j = 0; j <= rings; ++j) {
    const double theta = pi * j / rings;  // from the top
    for (int i = 0; i <= segments; ++i) {
      const double phi = 2 * pi * i / segments;
      const Vec3 n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      builder.add_vertex(Vec3{0, 0, radius_m} + radius_m * n, n);
    }
  }
  auto at = [&](int i, int j) { return static_cast<uint32_t>(j * (segments + 1) + i); };
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i) {
      // Counter-clockwise seen from outside; the pole rows' degenerate triangles are left out.
      if (j > 0) builder.add_triangle(at(i, j), at(i, j + 1), at(i + 1, j));
      if (j < rings - 1) builder.add_triangle(at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
    }
  return builder.finish();
}

Mesh make_cup_mesh(double outer_m, double inner_m, double height_m, double depth_m, int subdivisions) {
  const double h = outer_m / 2, a = inner_m / 2, H = height_m, D = depth_m, rim = h - a, F = H - D;
  const int n = subdivisions;
  MeshBuilder builder;
  // Outside: the four sides and the bottom, as the cube's.
  builder.add_grid({-h, -h, 0}, {0, outer_m, 0}, {outer_m, 0, 0}, n);  // bottom, -z
  builder.add_grid({h, -h, 0}, {0, outer_m, 0}, {0, 0, H}, n);         // +x
  builder.add_grid({-h, -h, 0}, {0, 0, H}, {0, outer_m, 0}, n);        // -x
  builder.add_grid({-h, h, 0}, {0, 0, H}, {outer_m, 0, 0}, n);         // +y
  builder.add_grid({-h, -h, 0}, {outer_m, 0, 0}, {0, 0, H}, n);        // -y
  // The rim around the pit's mouth, facing +z.
  builder.add_grid({-h, -h, H}, {outer_m, 0, 0}, {0, rim, 0}, n);
  builder.add_grid({-h, a, H}, {outer_m, 0, 0}, {0, rim, 0}, n);
  builder.add_grid({-h, -a, H}, {rim, 0, 0}, {0, inner_m, 0}, n);
  builder.add_grid({a, -a, H}, {rim, 0, 0}, {0, inner_m, 0}, n);
  // The pit: four walls facing its middle and its floor facing +z.
  builder.add_grid({-a, -a, F}, {0, inner_m, 0}, {0, 0, D}, n);  // at x = -a, facing +x
  builder.add_grid({a, -a, F}, {0, 0, D}, {0, inner_m, 0}, n);   // at x = +a, facing -x
  builder.add_grid({-a, -a, F}, {0, 0, D}, {inner_m, 0, 0}, n);  // at y = -a, facing +y
  builder.add_grid({-a, a, F}, {inner_m, 0, 0}, {0, 0, D}, n);   // at y = +a, facing -y
  builder.add_grid({-a, -a, F}, {inner_m, 0, 0}, {0, inner_m, 0}, n);  // floor
  return builder.finish();
}

Mesh make_plane_mesh(double edge_m, int subdivisions) {
  MeshBuilder builder;
  builder.add_grid({-edge_m / 2, -edge_m / 2, 0}, {edge_m, 0, 0}, {0, edge_m, 0}, subdivisions);  // facing +z
  return builder.finish();
}

Mesh make_box_mesh(const Vec3& size_m, int subdivisions) {
  const double x = size_m[0], y = size_m[1], z = size_m[2], hx = x / 2, hy = y / 2;
  MeshBuilder builder;
  builder.add_grid({-hx, -hy, z}, {x, 0, 0}, {0, y, 0}, subdivisions);  // top, +z
  builder.add_grid({-hx, -hy, 0}, {0, y, 0}, {x, 0, 0}, subdivisions);  // bottom, -z
  builder.add_grid({hx, -hy, 0}, {0, y, 0}, {0, 0, z}, subdivisions);   // +x
  builder.add_grid({-hx, -hy, 0}, {0, 0, z}, {0, y, 0}, subdivisions);  // -x
  builder.add_grid({-hx, hy, 0}, {0, 0, z}, {x, 0, 0}, subdivisions);   // +y
  builder.add_grid({-hx, -hy, 0}, {x, 0, 0}, {0, 0, z}, subdivisions);  // -y
  return builder.finish();
}

Mesh make_rectangle_mesh(double x_m, double y_m, int subdivisions) {
  MeshBuilder builder;
  builder.add_grid({-x_m / 2, -y_m / 2, 0}, {x_m, 0, 0}, {0, y_m, 0}, subdivisions);  // facing +z
  return builder.finish();
}

Mesh make_cylinder_mesh(const Vec3& size_m, int segments, int subdivisions) {
  const double a = size_m[0] / 2, b = size_m[1] / 2, height = size_m[2];
  const double pi = 3.14159265358979323846;
  segments = std::max(segments, 3);
  subdivisions = std::max(subdivisions, 1);
  MeshBuilder builder;
  // The side: `subdivisions` rings up the height (lens distortion bends long edges), smooth
  // normals of the ellipse (x / a^2, y / b^2).
  const uint32_t side = static_cast<uint32_t>(builder.vertex_count());
  for (int j = 0; j <= subdivisions; ++j)
    for (int i = 0; i <= segments; ++i) {
      // The seam's column repeats the first by value, so the surface welds closed there.
      const double phi = 2 * pi * (i % segments) / segments, c = std::cos(phi), s = std::sin(phi);
      builder.add_vertex({a * c, b * s, height * j / subdivisions}, normalized(Vec3{c / a, s / b, 0}));
    }
  auto at = [&](int i, int j) { return side + static_cast<uint32_t>(j * (segments + 1) + i); };
  for (int j = 0; j < subdivisions; ++j)
    for (int i = 0; i < segments; ++i) {  // counter-clockwise seen from outside
      builder.add_triangle(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      builder.add_triangle(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  // The caps: fans from the centre, split into rings so that no edge is long.
  for (const bool top : {true, false}) {
    const double z = top ? height : 0;
    const Vec3 normal{0, 0, top ? 1.0 : -1.0};
    const uint32_t centre = builder.add_vertex({0, 0, z}, normal);
    const uint32_t first = static_cast<uint32_t>(builder.vertex_count());
    for (int r = 1; r <= subdivisions; ++r)
      for (int i = 0; i < segments; ++i) {
        const double phi = 2 * pi * i / segments, f = double(r) / subdivisions;
        builder.add_vertex({f * a * std::cos(phi), f * b * std::sin(phi), z}, normal);
      }
    auto ring = [&](int r, int i) { return first + static_cast<uint32_t>((r - 1) * segments + (i % segments)); };
    for (int i = 0; i < segments; ++i) {
      if (top) builder.add_triangle(centre, ring(1, i), ring(1, i + 1));
      else builder.add_triangle(centre, ring(1, i + 1), ring(1, i));
      for (int r = 1; r < subdivisions; ++r) {
        if (top) {
          builder.add_triangle(ring(r, i), ring(r + 1, i), ring(r + 1, i + 1));
          builder.add_triangle(ring(r, i), ring(r + 1, i + 1), ring(r, i + 1));
        } else {
          builder.add_triangle(ring(r, i), ring(r + 1, i + 1), ring(r + 1, i));
          builder.add_triangle(ring(r, i), ring(r, i + 1), ring(r + 1, i + 1));
        }
      }
    }
  }
  return builder.finish();
}

bool is_builtin_mesh_source(std::string_view source) { return source.substr(0, kBuiltinMeshPrefix.size()) == kBuiltinMeshPrefix; }

std::optional<Mesh> make_builtin_mesh(std::string_view source) {
  std::optional<Mesh> mesh;
  if (source == "builtin:cube") mesh = make_cube_mesh();
  if (source == "builtin:pyramid") mesh = make_pyramid_mesh();
  if (source == "builtin:sphere") mesh = make_sphere_mesh();
  if (source == "builtin:cup") mesh = make_cup_mesh();
  if (source == "builtin:box") mesh = make_box_mesh();
  if (source == "builtin:cylinder") mesh = make_cylinder_mesh();
  if (source == "builtin:plane") mesh = make_rectangle_mesh();
  if (mesh) mesh->source = std::string(source);  // messages about the mesh (a PRT bake's) name it
  return mesh;
}

bool builtin_mesh_is_sized(std::string_view source) {
  return source == "builtin:box" || source == "builtin:cylinder" || source == "builtin:plane";
}

std::optional<Mesh> make_builtin_mesh(std::string_view source, const Vec3& size_m, int subdivisions) {
  subdivisions = std::max(subdivisions, 1);
  std::optional<Mesh> mesh;
  if (source == "builtin:cube") mesh = make_cube_mesh(0.06, subdivisions);
  else if (source == "builtin:pyramid") mesh = make_pyramid_mesh(0.06, 0.06, subdivisions);
  else if (source == "builtin:box") mesh = make_box_mesh(size_m, subdivisions);
  else if (source == "builtin:cylinder") mesh = make_cylinder_mesh(size_m, 48, subdivisions);
  else if (source == "builtin:plane") mesh = make_rectangle_mesh(size_m[0], size_m[1], subdivisions);
  else return make_builtin_mesh(source);
  mesh->source = std::string(source);
  return mesh;
}

}  // namespace arpipe
