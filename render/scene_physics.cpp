// The config's rigid-body world (see scene_physics.h).
#include "render/scene_physics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/physics/physics_error.h"
#include "core/scene/builtin_meshes.h"

namespace arpipe {
namespace {

std::string config_label(const Config& config) { return config.file.empty() ? std::string("config") : config.file.string(); }

// A primitive fitted to a mesh's bounds (object frame, scaled): where its centre is and its size.
struct Fitted {
  Vec3 centre;
  Vec3 half;
};
Fitted fitted(const Mesh& mesh, const Vec3& scale) {
  const Bounds b = mesh.bounds();
  Fitted out;
  for (size_t k = 0; k < 3; ++k) {
    out.centre[k] = 0.5 * (b.min[k] + b.max[k]) * scale[k];
    out.half[k] = 0.5 * (b.max[k] - b.min[k]) * std::abs(scale[k]);
  }
  return out;
}

SE3 shifted(const Vec3& t) { return SE3(SE3::identity().rotation(), t); }

// What `auto` means for a mesh source: the primitive a builtin is, else nothing (a mesh shape).
enum class Primitive { None, Sphere, Box, Cylinder };
Primitive builtin_primitive(const std::string& source, const Mesh& mesh) {
  if (source == "builtin:sphere") return Primitive::Sphere;
  if (source == "builtin:cube" || source == "builtin:box" || source == "builtin:plane") return Primitive::Box;
  if (source == "builtin:cylinder") {
    const Bounds b = mesh.bounds();
    // Bullet's cylinder has a circular section; an elliptic one collides as its hull.
    return std::abs((b.max[0] - b.min[0]) - (b.max[1] - b.min[1])) < 1e-9 ? Primitive::Cylinder : Primitive::None;
  }
  return Primitive::None;
}

// The shape for a primitive fitted to the mesh, and where it sits in the object's frame.
template <class Shape>
Shape primitive_shape(Primitive primitive, const Mesh& mesh, double scale, SE3& T_object_shape) {
  const Fitted f = fitted(mesh, {scale, scale, scale});
  T_object_shape = shifted(f.centre);
  switch (primitive) {
    case Primitive::Sphere: return SphereShape{std::max({f.half[0], f.half[1], f.half[2]})};
    case Primitive::Cylinder: return CylinderShape{std::max(f.half[0], f.half[1]), f.half[2]};
    // A plane is flat: a 1 mm slab under its face, so that bodies land on the face itself.
    case Primitive::Box: {
      Vec3 half = f.half;
      if (half[2] < 5e-4) {
        half[2] = 5e-4;
        T_object_shape = shifted({f.centre[0], f.centre[1], f.centre[2] - 5e-4});
      }
      return BoxShape{half};
    }
    case Primitive::None: break;
  }
  return Shape{};
}

RigidWorldSettings world_settings(const PhysicsConfig& physics, int64_t history_floor_ns) {
  RigidWorldSettings s;
  s.gravity_mps2 = physics.gravity_mps2;
  s.substep_hz = physics.substep_hz;
  s.max_substeps_per_advance = std::max<int64_t>(1, physics.max_advance_ns * physics.substep_hz / 1'000'000'000);
  s.history_ns = std::max(physics.history_ns, history_floor_ns);
  s.floor_limit_z_m = physics.floor_limit_z_m;
  s.world_radius_m = physics.world_radius_m;
  s.solver_iterations = physics.solver_iterations;
  return s;
}

}  // namespace

ScenePhysics::ScenePhysics(const Config& config, const LoadedMeshes& meshes)
    : settings_(world_settings(config.render.physics, 0)) {
  const RenderConfig& render = config.render;
  body_of_object_.assign(render.objects.size(), std::nullopt);
  for (size_t i = 0; i < render.objects.size() && i < meshes.mesh_of_object.size(); ++i) {
    const SceneObject& object = render.objects[i];
    const ObjectPhysics& p = object.physics;
    if (p.kind == ObjectMotion::None) continue;
    const Mesh& mesh = meshes.meshes[meshes.mesh_of_object[i]].mesh;
    RigidBodySpec spec;
    spec.name = fmt::format("render.objects[{}]", i);
    spec.kind = p.kind == ObjectMotion::Static ? BodyKind::Static
                : p.kind == ObjectMotion::Kinematic ? BodyKind::Kinematic
                                                    : BodyKind::Dynamic;
    spec.mass_kg = p.mass_kg;
    spec.linear_velocity_mps = p.velocity_mps;
    spec.angular_velocity_radps = p.spin_radps;
    spec.restitution = p.restitution;
    spec.friction = p.friction;
    spec.rolling_friction = p.rolling_friction;
    spec.linear_damping = p.linear_damping;
    spec.angular_damping = p.angular_damping;
    spec.T_world_body = SE3::from_rt({0, 0, object.yaw_rad}, object.position_m);
    Primitive primitive = Primitive::None;
    switch (p.shape) {
      case BodyShapeChoice::Auto: primitive = builtin_primitive(object.mesh, mesh); break;
      case BodyShapeChoice::Sphere: primitive = Primitive::Sphere; break;
      case BodyShapeChoice::Box: primitive = Primitive::Box; break;
      case BodyShapeChoice::Cylinder: primitive = Primitive::Cylinder; break;
      case BodyShapeChoice::Hull: break;
    }
    if (primitive == Primitive::None)
      spec.shape = MeshShape{std::make_shared<const Mesh>(mesh), {object.scale, object.scale, object.scale}, MeshCollision::ConvexHull};
    else
      spec.shape = primitive_shape<BodyShape>(primitive, mesh, object.scale, spec.T_body_shape);
    for (const PoseKey& key : p.track)
      spec.track.push_back({std::llround(key.time_s * 1e9), SE3::from_rt({0, 0, key.yaw_rad}, key.position_m)});
    body_of_object_[i] = bodies_.size();
    bodies_.push_back({i, std::move(spec)});
  }
  if (bodies_.empty()) return;  // colliders alone move nothing

  if (render.physics.ground) {
    ColliderSpec ground;
    ground.name = "ground (render.physics.ground)";
    ground.T_world_collider = shifted({0, 0, render.shadows.receiver_height_m});
    colliders_.push_back(ground);
    collider_viewpoint_.push_back(-1);
  }
  for (size_t i = 0; i < render.proxies.size() && i < meshes.proxies.size(); ++i) {
    const SceneProxy& proxy = render.proxies[i];
    if (!proxy.roles.collide) continue;
    const Mesh& mesh = meshes.proxies[i].collision ? *meshes.proxies[i].collision : *meshes.proxies[i].mesh;
    ColliderSpec spec;
    spec.name = fmt::format("render.proxies[{}]{}", i, proxy.name.empty() ? "" : fmt::format(" (\"{}\")", proxy.name));
    spec.restitution = proxy.restitution;
    spec.friction = proxy.friction;
    // A glTF node's proxy stands where its file puts the node (an animated one cannot collide).
    const ScaledPose rest = proxy_rest_placement(proxy, meshes.proxies[i]);
    const SE3& T_world_proxy = rest.pose;
    Primitive primitive = Primitive::None;
    MeshCollision collision = MeshCollision::Triangles;
    switch (proxy.collider) {
      case ColliderChoice::Auto: primitive = proxy.collision_mesh.empty() ? builtin_primitive(proxy.mesh, mesh) : Primitive::None; break;
      case ColliderChoice::Triangles: break;
      case ColliderChoice::Hull: collision = MeshCollision::ConvexHull; break;
      case ColliderChoice::Box: primitive = Primitive::Box; break;
      case ColliderChoice::Sphere: primitive = Primitive::Sphere; break;
      case ColliderChoice::Cylinder: primitive = Primitive::Cylinder; break;
    }
    // An elliptic builtin cylinder under auto: its hull is exact (it is convex).
    if (primitive == Primitive::None && proxy.collider == ColliderChoice::Auto && proxy.mesh == "builtin:cylinder" &&
        proxy.collision_mesh.empty())
      collision = MeshCollision::ConvexHull;
    SE3 T_proxy_shape;
    if (primitive == Primitive::None)
      spec.shape = MeshShape{std::make_shared<const Mesh>(mesh), {rest.scale, rest.scale, rest.scale}, collision};
    else
      spec.shape = primitive_shape<ColliderShape>(primitive, mesh, rest.scale, T_proxy_shape);
    spec.T_world_collider = T_world_proxy * T_proxy_shape;
    colliders_.push_back(std::move(spec));
    collider_viewpoint_.push_back(proxy.viewpoint);
  }
  // Every spec is checked now, where the config's name can go into the message: a trial world
  // takes them all (Bullet builds each shape; a 10k-triangle proxy takes milliseconds).
  try {
    build(0);
  } catch (const PhysicsError& e) {
    throw ConfigError(fmt::format("{}: physics: {}", config_label(config), e.what()));
  }
  world_.reset();
}

ScenePhysics::~ScenePhysics() = default;

void ScenePhysics::build(int64_t t0_ns) {
  auto world = std::make_unique<RigidWorld>(settings_);
  for (const ColliderSpec& collider : colliders_) world->add_collider(collider);
  for (const Body& body : bodies_) {
    RigidBodySpec spec = body.spec;
    for (BodyPoseKey& key : spec.track) key.time_ns += t0_ns;
    world->add_body(spec);
  }
  world->start(t0_ns);
  world_ = std::move(world);
  start_ns_ = t0_ns;
  set_viewpoint(viewpoint_);
}

void ScenePhysics::set_viewpoint(const std::optional<int>& viewpoint) {
  viewpoint_ = viewpoint;
  if (!world_) return;
  for (size_t i = 0; i < collider_viewpoint_.size(); ++i)
    world_->set_collider_enabled(i, collider_viewpoint_[i] < 0 || !viewpoint || collider_viewpoint_[i] == *viewpoint);
}

void ScenePhysics::advance(int64_t exposure_start_ns, int64_t end_ns) {
  if (bodies_.empty()) return;
  if (!world_ || exposure_start_ns < last_start_ns_) {
    if (world_) ++restarts_;
    build(exposure_start_ns);
  }
  last_start_ns_ = exposure_start_ns;
  world_->advance_to(end_ns);
}

std::optional<BodySample> ScenePhysics::sample(size_t object_index, int64_t t_ns) const {
  if (!world_ || object_index >= body_of_object_.size() || !body_of_object_[object_index]) return std::nullopt;
  return world_->sample_at(*body_of_object_[object_index], t_ns);
}

}  // namespace arpipe
