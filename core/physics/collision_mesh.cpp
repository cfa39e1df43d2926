// Collision meshes: the checks run in one pass over the vertices and one over the triangles; the
// manifold check welds positions by exact value (builtin meshes repeat corners per face).
#include "core/physics/collision_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include "core/physics/physics_error.h"
#include "core/physics/physics_limits.h"

namespace arpipe {

namespace {

namespace lim = physics_limits;

std::string collision_mesh_label(const std::string& who, const Mesh& mesh) {
  if (mesh.source.empty()) return who + ": shape.mesh";
  return fmt::format("{}: shape.mesh \"{}\"", who, mesh.source);
}

// Each vertex's welded id: vertices with bit-identical positions share one.
std::vector<uint32_t> weld_collision_vertices(const Mesh& mesh) {
  std::map<std::array<float, 3>, uint32_t> ids;
  std::vector<uint32_t> welded(mesh.vertex_count());
  for (size_t v = 0; v < welded.size(); ++v) {
    const std::array<float, 3> p{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
    welded[v] = ids.emplace(p, static_cast<uint32_t>(ids.size())).first->second;
  }
  return welded;
}

// An edge of more than two triangles cannot bound a solid: contacts along it have no one normal.
void check_collision_manifold(const Mesh& mesh, const std::string& label, const CollisionMesh& out) {
  const std::vector<uint32_t> welded = weld_collision_vertices(mesh);
  std::unordered_map<uint64_t, uint32_t> edge_use;
  edge_use.reserve(out.triangles.size() * 3);
  for (size_t t = 0; t < out.triangles.size(); ++t) {
    const auto& tri = out.triangles[t];
    for (int e = 0; e < 3; ++e) {
      uint32_t a = welded[tri[e]], b = welded[tri[(e + 1) % 3]];
      if (a > b) std::swap(a, b);
      if (++edge_use[(uint64_t{a} << 32) | b] > 2) {
        const Vec3& p = out.vertices[tri[e]];
        const Vec3& q = out.vertices[tri[(e + 1) % 3]];
        throw PhysicsError(fmt::format(
            "{}: not manifold for collision: the edge from vertex {} ({:.6g}, {:.6g}, {:.6g}) to vertex {} ({:.6g}, "
            "{:.6g}, {:.6g}) belongs to more than two triangles (the third: triangle {} of the non-degenerate ones)",
            label, tri[e], p[0], p[1], p[2], tri[(e + 1) % 3], q[0], q[1], q[2], t));
      }
    }
  }
}

}  // namespace

CollisionMesh make_collision_mesh(const MeshShape& shape, const std::string& who) {
  if (!shape.mesh) throw PhysicsError(who + ": shape.mesh: no mesh given");
  const Mesh& mesh = *shape.mesh;
  const std::string label = collision_mesh_label(who, mesh);
  if (mesh.positions.size() % 3 != 0)
    throw PhysicsError(fmt::format("{}: {} position floats, not three per vertex", label, mesh.positions.size()));
  const size_t vertex_count = mesh.vertex_count();
  if (vertex_count == 0) throw PhysicsError(label + ": the mesh is empty (no vertices)");
  if (vertex_count > lim::kMaxVerticesPerMesh)
    throw PhysicsError(fmt::format("{}: {} vertices, more than the limit of {}", label, vertex_count, lim::kMaxVerticesPerMesh));

  CollisionMesh out;
  out.vertices.resize(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) {
    for (int c = 0; c < 3; ++c) {
      const double x = mesh.positions[3 * v + c];
      if (!std::isfinite(x))
        throw PhysicsError(fmt::format("{}: vertex {} has a non-finite coordinate ({}, {}, {})", label, v,
                                       mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]));
      out.vertices[v][c] = x * shape.scale[c];
      if (std::abs(out.vertices[v][c]) > lim::kMaxSizeM)
        throw PhysicsError(fmt::format("{}: vertex {} lies {:.6g} m from the shape's origin after scaling, beyond the "
                                       "limit of {} m", label, v, std::abs(out.vertices[v][c]), lim::kMaxSizeM));
    }
  }
  if (shape.collision == MeshCollision::ConvexHull) return out;

  if (mesh.indices.size() % 3 != 0)
    throw PhysicsError(fmt::format("{}: {} indices, not three per triangle", label, mesh.indices.size()));
  const size_t triangle_count = mesh.triangle_count();
  if (triangle_count == 0) throw PhysicsError(label + ": the mesh has no triangles to collide with");
  if (triangle_count > lim::kMaxTrianglesPerMesh)
    throw PhysicsError(
        fmt::format("{}: {} triangles, more than the limit of {}", label, triangle_count, lim::kMaxTrianglesPerMesh));
  out.triangles.reserve(triangle_count);
  for (size_t t = 0; t < triangle_count; ++t) {
    const std::array<uint32_t, 3> tri{mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]};
    for (uint32_t i : tri)
      if (i >= vertex_count)
        throw PhysicsError(fmt::format("{}: triangle {} names vertex {}, but the mesh has {} vertices", label, t, i,
                                       vertex_count));
    const Vec3 n = cross(out.vertices[tri[1]] - out.vertices[tri[0]], out.vertices[tri[2]] - out.vertices[tri[0]]);
    // Zero area (repeated or collinear corners): no normal to collide along; Bullet would divide by it.
    if (!(norm(n) > 1e-12)) {
      ++out.degenerate_triangles;
      continue;
    }
    out.triangles.push_back(tri);
  }
  if (out.triangles.empty())
    throw PhysicsError(fmt::format("{}: all {} triangles are degenerate (zero area)", label, triangle_count));
  check_collision_manifold(mesh, label, out);
  return out;
}

}  // namespace arpipe
