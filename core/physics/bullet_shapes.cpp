// Bullet shapes. Primitives map one to one (Bullet's box and cylinder keep their outer size: their
// margin lies inside). A convex hull is computed once, shrunk by its margin so that the margin
// restores the outer surface, and re-centred on its volume centroid (Bullet rotates a body about
// its shape's origin). Triangles go to a BVH shape.
#include "core/physics/bullet_shapes.h"

#include <LinearMath/btConvexHullComputer.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/physics/collision_mesh.h"
#include "core/physics/physics_error.h"

namespace arpipe {

namespace {

// Bullet's collision margin. A box, cylinder or hull is its core dilated by the margin, so the
// margin rounds every edge and corner with this radius (Bullet's default, 4 cm, would make a ball
// leave a table 4 cm before its edge). Boxes and cylinders keep their outer size when it is set;
// a hull is shrunk by it first (clamped to a quarter of a thin hull's depth).
constexpr double kShapeMarginM = 0.001;

// At most a tenth of the smallest half size, so tiny shapes keep a core.
btScalar primitive_margin(double smallest_half_size_m) {
  return static_cast<btScalar>(std::min(kShapeMarginM, 0.1 * smallest_half_size_m));
}

btVector3 to_bt_vector(const Vec3& v) {
  return {static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2])};
}

BulletShape make_bullet_primitive(const SphereShape& s) {
  BulletShape out;
  out.shape = std::make_unique<btSphereShape>(static_cast<btScalar>(s.radius_m));
  return out;
}

BulletShape make_bullet_primitive(const BoxShape& s) {
  BulletShape out;
  out.shape = std::make_unique<btBoxShape>(to_bt_vector(s.half_extents_m));
  out.shape->setMargin(
      primitive_margin(std::min(s.half_extents_m[0], std::min(s.half_extents_m[1], s.half_extents_m[2]))));
  return out;
}

BulletShape make_bullet_primitive(const CylinderShape& s) {
  BulletShape out;
  out.shape = std::make_unique<btCylinderShapeZ>(to_bt_vector({s.radius_m, s.radius_m, s.half_height_m}));
  out.shape->setMargin(primitive_margin(std::min(s.radius_m, s.half_height_m)));
  return out;
}

BulletShape make_bullet_primitive(const PlaneShape&) {
  BulletShape out;
  out.shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), btScalar(0));
  return out;
}

BulletShape make_bullet_hull(const MeshShape& s, const std::string& who) {
  const CollisionMesh mesh = make_collision_mesh(s, who);
  std::vector<double> coords;
  coords.reserve(mesh.vertices.size() * 3);
  for (const Vec3& v : mesh.vertices) coords.insert(coords.end(), v.begin(), v.end());
  btConvexHullComputer hull;
  const btScalar shrink = hull.compute(coords.data(), static_cast<int>(3 * sizeof(double)),
                                       static_cast<int>(mesh.vertices.size()), kShapeMarginM, 0.25);
  if (shrink < 0 || hull.vertices.size() < 4 || hull.faces.size() < 4)
    throw PhysicsError(who + ": shape.mesh: its convex hull has no volume (the vertices are flat, on a line or one point)");

  // Volume and centroid: a fan of tetrahedra from one hull vertex over every face.
  const btVector3 apex = hull.vertices[0];
  double volume6 = 0;
  Vec3 weighted{0, 0, 0};
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* first = &hull.edges[hull.faces[f]];
    const int a = first->getSourceVertex();
    for (const btConvexHullComputer::Edge* e = first->getNextEdgeOfFace(); e->getTargetVertex() != a;
         e = e->getNextEdgeOfFace()) {
      const btVector3 pa = hull.vertices[a] - apex, pb = hull.vertices[e->getSourceVertex()] - apex,
                      pc = hull.vertices[e->getTargetVertex()] - apex;
      const double v6 = static_cast<double>(pa.dot(pb.cross(pc)));
      volume6 += v6;
      const btVector3 c = (pa + pb + pc) * btScalar(0.25);
      weighted = weighted + v6 * Vec3{c.x(), c.y(), c.z()};
    }
  }
  if (!(std::abs(volume6) > 1e-18))
    throw PhysicsError(who + ": shape.mesh: its convex hull has no volume (the vertices are flat)");
  const Vec3 centroid = Vec3{apex.x(), apex.y(), apex.z()} + (1.0 / volume6) * weighted;

  auto shape = std::make_unique<btConvexHullShape>();
  const btVector3 c = to_bt_vector(centroid);
  for (int v = 0; v < hull.vertices.size(); ++v) shape->addPoint(hull.vertices[v] - c, false);
  shape->recalcLocalAabb();
  shape->setMargin(shrink);
  BulletShape out;
  out.shape = std::move(shape);
  out.centre_of_mass = centroid;
  return out;
}

BulletShape make_bullet_triangles(const MeshShape& s, const std::string& who) {
  const CollisionMesh mesh = make_collision_mesh(s, who);
  BulletShape out;
  out.triangle_data = std::make_unique<btTriangleMesh>(true, false);
  out.triangle_data->preallocateVertices(static_cast<int>(mesh.vertices.size() * 3));
  out.triangle_data->preallocateIndices(static_cast<int>(mesh.triangles.size() * 3));
  for (const Vec3& v : mesh.vertices) out.triangle_data->findOrAddVertex(to_bt_vector(v), false);
  for (const auto& t : mesh.triangles)
    out.triangle_data->addTriangleIndices(static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2]));
  out.shape = std::make_unique<btBvhTriangleMeshShape>(out.triangle_data.get(), true);
  out.degenerate_triangles = mesh.degenerate_triangles;
  return out;
}

BulletShape make_bullet_mesh(const MeshShape& s, const std::string& who) {
  return s.collision == MeshCollision::ConvexHull ? make_bullet_hull(s, who) : make_bullet_triangles(s, who);
}

size_t mesh_shape_triangle_count(const MeshShape& s) {
  return s.mesh && s.collision == MeshCollision::Triangles ? s.mesh->triangle_count() : 0;
}

}  // namespace

BulletShape make_bullet_body_shape(const BodyShape& shape, const std::string& who) {
  if (const auto* mesh = std::get_if<MeshShape>(&shape)) return make_bullet_mesh(*mesh, who);
  return std::visit(
      [](const auto& s) -> BulletShape {
        if constexpr (std::is_same_v<std::decay_t<decltype(s)>, MeshShape>) return {};
        else return make_bullet_primitive(s);
      },
      shape);
}

BulletShape make_bullet_collider_shape(const ColliderShape& shape, const std::string& who) {
  if (const auto* mesh = std::get_if<MeshShape>(&shape)) return make_bullet_mesh(*mesh, who);
  return std::visit(
      [](const auto& s) -> BulletShape {
        if constexpr (std::is_same_v<std::decay_t<decltype(s)>, MeshShape>) return {};
        else return make_bullet_primitive(s);
      },
      shape);
}

size_t bullet_shape_triangle_count(const BodyShape& shape) {
  const auto* mesh = std::get_if<MeshShape>(&shape);
  return mesh ? mesh_shape_triangle_count(*mesh) : 0;
}

size_t bullet_shape_triangle_count(const ColliderShape& shape) {
  const auto* mesh = std::get_if<MeshShape>(&shape);
  return mesh ? mesh_shape_triangle_count(*mesh) : 0;
}

}  // namespace arpipe
