// Concave PRT test meshes built from flat grids.
#include "render/prt/prt_test_meshes.h"

namespace arpipe {
namespace {

// The parallelogram origin + s u + t v, s and t in [0, 1], as an n x n grid facing u x v.
void add_grid(Mesh& mesh, const Vec3& origin, const Vec3& u, const Vec3& v, int n) {
  const Vec3 normal = normalized(cross(u, v));
  const auto first = uint32_t(mesh.vertex_count());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec3 p = origin + (double(i) / n) * u + (double(j) / n) * v;
      for (size_t k = 0; k < 3; ++k) {
        mesh.positions.push_back(float(p[k]));
        mesh.normals.push_back(float(normal[k]));
      }
    }
  auto at = [&](int i, int j) { return first + uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
}

Mesh finish(Mesh mesh) {
  mesh.parts = {MeshPart{0, uint32_t(mesh.indices.size()), {1, 1, 1, 1}}};
  return mesh;
}

}  // namespace

Mesh make_open_box(double side, double height, int subdivisions) {
  const double s = side, h = side / 2, H = height;
  Mesh mesh;
  add_grid(mesh, {-h, -h, 0}, {s, 0, 0}, {0, s, 0}, subdivisions);  // floor, +z
  add_grid(mesh, {-h, -h, 0}, {0, s, 0}, {0, 0, H}, subdivisions);  // x = -h, facing +x
  add_grid(mesh, {h, -h, 0}, {0, 0, H}, {0, s, 0}, subdivisions);   // x = +h, facing -x
  add_grid(mesh, {-h, -h, 0}, {0, 0, H}, {s, 0, 0}, subdivisions);  // y = -h, facing +y
  add_grid(mesh, {-h, h, 0}, {s, 0, 0}, {0, 0, H}, subdivisions);   // y = +h, facing -y
  return finish(std::move(mesh));
}

Mesh make_floor_with_wall(double half_width, double depth, double height, int subdivisions) {
  Mesh mesh;
  add_grid(mesh, {-half_width, 0, 0}, {2 * half_width, 0, 0}, {0, depth, 0}, subdivisions);  // floor, +z
  add_grid(mesh, {-half_width, 0, 0}, {0, 0, height}, {2 * half_width, 0, 0}, subdivisions);  // wall, +y
  return finish(std::move(mesh));
}

}  // namespace arpipe
