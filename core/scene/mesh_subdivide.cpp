// Longest-edge bisection to a maximum edge length.
#include "core/scene/mesh_subdivide.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace arpipe {
namespace {

Vec3 position(const Mesh& mesh, uint32_t v) {
  return {mesh.positions[3 * size_t(v)], mesh.positions[3 * size_t(v) + 1], mesh.positions[3 * size_t(v) + 2]};
}

double edge_length(const Mesh& mesh, uint32_t a, uint32_t b) { return norm(position(mesh, a) - position(mesh, b)); }

// Triangles the bisection makes of one triangle whose longest edge is `longest`: at most about
// 2 (longest / max_edge)^2 (each halving of the edges quarters the triangle).
double estimated_triangles(double longest, double max_edge) {
  const double ratio = std::ceil(longest / max_edge);
  return 2 * ratio * ratio;
}

class Bisector {
 public:
  // values: values_per_vertex floats a vertex of out, carried to each midpoint as the ends' mean.
  Bisector(Mesh& out, double max_edge, std::vector<float>* values = nullptr, size_t values_per_vertex = 0)
      : out_(out), max_edge_(max_edge), values_(values), per_vertex_(values ? values_per_vertex : 0) {}

  void split(uint32_t a, uint32_t b, uint32_t c, int depth = 0) {
    const double ab = edge_length(out_, a, b), bc = edge_length(out_, b, c), ca = edge_length(out_, c, a);
    const double longest = std::max({ab, bc, ca});
    if (longest <= max_edge_ || depth > 40) {
      out_.indices.insert(out_.indices.end(), {a, b, c});
      return;
    }
    // Rotate so that (a, b) is the longest edge, keeping the winding.
    if (bc == longest) std::tie(a, b, c) = std::make_tuple(b, c, a);
    else if (ca == longest) std::tie(a, b, c) = std::make_tuple(c, a, b);
    const uint32_t m = midpoint(a, b);
    split(a, m, c, depth + 1);
    split(m, b, c, depth + 1);
  }

 private:
  uint32_t midpoint(uint32_t a, uint32_t b) {
    const std::pair<uint32_t, uint32_t> key = std::minmax(a, b);
    if (const auto found = midpoints_.find(key); found != midpoints_.end()) return found->second;
    const uint32_t m = uint32_t(out_.vertex_count());
    for (size_t k = 0; k < 3; ++k)  // from the ordered pair: the same bits from either side
      out_.positions.push_back(0.5f * (out_.positions[3 * size_t(key.first) + k] + out_.positions[3 * size_t(key.second) + k]));
    if (!out_.normals.empty()) {
      Vec3 n{0, 0, 0};
      for (size_t k = 0; k < 3; ++k) n[k] = double(out_.normals[3 * size_t(a) + k]) + out_.normals[3 * size_t(b) + k];
      const double length = norm(n);
      n = length > 0 ? (1.0 / length) * n : Vec3{0, 0, 1};
      out_.normals.insert(out_.normals.end(), {float(n[0]), float(n[1]), float(n[2])});
    }
    for (size_t k = 0; k < per_vertex_; ++k)
      values_->push_back(0.5f * ((*values_)[per_vertex_ * key.first + k] + (*values_)[per_vertex_ * key.second + k]));
    midpoints_.emplace(key, m);
    return m;
  }

  Mesh& out_;
  double max_edge_;
  std::vector<float>* values_;
  size_t per_vertex_;
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints_;
};

Mesh cut(const Mesh& mesh, std::vector<float>* values, size_t values_per_vertex, double max_edge_m, size_t max_triangles,
         double* used_edge_m) {
  double estimate = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    estimate += estimated_triangles(std::max({edge_length(mesh, a, b), edge_length(mesh, b, c), edge_length(mesh, c, a)}), max_edge_m);
  }
  double edge = max_edge_m;
  if (estimate > double(max_triangles)) edge *= std::sqrt(estimate / double(max_triangles));
  if (used_edge_m) *used_edge_m = edge;

  Mesh out;
  out.positions = mesh.positions;
  out.normals = mesh.normals.size() == mesh.positions.size() ? mesh.normals : std::vector<float>{};
  out.source = mesh.source;
  Bisector bisector(out, edge, values, values_per_vertex);
  std::vector<MeshPart> parts = mesh.parts;
  if (parts.empty()) parts.push_back(MeshPart{0, uint32_t(mesh.indices.size()), {1, 1, 1, 1}});
  for (const MeshPart& part : parts) {
    MeshPart piece = part;
    piece.first_index = uint32_t(out.indices.size());
    for (size_t t = part.first_index; t + 2 < size_t(part.first_index) + part.index_count && t + 2 < mesh.indices.size(); t += 3)
      bisector.split(mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]);
    piece.index_count = uint32_t(out.indices.size() - piece.first_index);
    out.parts.push_back(piece);
  }
  if (mesh.parts.empty()) out.parts.clear();
  return out;
}

}  // namespace

Mesh subdivided(const Mesh& mesh, double max_edge_m, size_t max_triangles, double* used_edge_m) {
  return cut(mesh, nullptr, 0, max_edge_m, max_triangles, used_edge_m);
}

Mesh subdivided(const Mesh& mesh, std::vector<float>& vertex_values, size_t values_per_vertex, double max_edge_m,
                size_t max_triangles, double* used_edge_m) {
  if (vertex_values.size() != values_per_vertex * mesh.vertex_count())
    throw std::invalid_argument("subdivided: the vertex values are not values_per_vertex a vertex");
  return cut(mesh, &vertex_values, values_per_vertex, max_edge_m, max_triangles, used_edge_m);
}

}  // namespace arpipe
