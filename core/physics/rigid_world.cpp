// RigidWorld over Bullet's btDiscreteDynamicsWorld. Each substep is one stepSimulation(dt, 0):
// Bullet's "variable" mode with our fixed dt, so Bullet keeps no clock or interpolation of its own
// and the substep grid (substep_clock.h) alone decides what runs when.
#include "core/physics/rigid_world.h"

#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/physics/bounce_solver.h"
#include "core/physics/bullet_shapes.h"
#include "core/physics/kinematic_track.h"
#include "core/physics/physics_error.h"
#include "core/physics/physics_limits.h"
#include "core/physics/spec_checks.h"
#include "core/physics/substep_clock.h"
#include "core/physics/substep_history.h"

namespace arpipe {

namespace {

namespace lim = physics_limits;

// Timestamps beyond this are refused: the substep grid adds up to a second to them.
constexpr int64_t kMaxUsableTimeNs = int64_t{1} << 62;
// Substep states (snapshots x bodies) a world may keep: about 110 bytes each.
constexpr uint64_t kMaxHistoryStates = 4'000'000;

btTransform to_bt_transform(const SE3& T) {
  const Mat3& R = T.rotation();
  const btMatrix3x3 basis(static_cast<btScalar>(R[0][0]), static_cast<btScalar>(R[0][1]), static_cast<btScalar>(R[0][2]),
                          static_cast<btScalar>(R[1][0]), static_cast<btScalar>(R[1][1]), static_cast<btScalar>(R[1][2]),
                          static_cast<btScalar>(R[2][0]), static_cast<btScalar>(R[2][1]), static_cast<btScalar>(R[2][2]));
  const Vec3& t = T.translation();
  return btTransform(basis, btVector3(static_cast<btScalar>(t[0]), static_cast<btScalar>(t[1]), static_cast<btScalar>(t[2])));
}

// Contacts are solved once the shapes are at most 0.1 mm apart. Bullet's default solves contacts up
// to its breaking threshold (about a millimetre here) apart, and a bounce found that early leaves
// from there (bounce_solver.h); with none at all (0), resting contacts come and go every other
// substep and a stack of boxes creeps sideways.
constexpr btScalar kContactProcessingThresholdM = 1e-4f;

// The share of a penetration the split impulse removes per substep. A ball that bounced inside
// the ground leaves from there; with Bullet's 0.2 most of that depth is never made up and bounces
// came out 4 % too low (e = 0.3); 0.8 removes it before the ball has left (tests/physics/free_fall_test.cpp).
constexpr btScalar kSplitImpulseErp = 0.8f;

// A flat face on a plane or a face gets several contact points at once (Bullet's perturbation),
// not one that wanders from corner to corner: boxes and hulls then land and stand still.
btDefaultCollisionConfiguration* with_multipoint_contacts(btDefaultCollisionConfiguration& config) {
  config.setConvexConvexMultipointIterations();
  config.setPlaneConvexMultipointIterations();
  return &config;
}

Vec3 from_bt_vector(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

SE3 rigid_translation(const Vec3& t) { return SE3(identity3(), t); }

bool rigid_state_finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

const char* removal_reason_name(RemovalReason reason) {
  switch (reason) {
    case RemovalReason::None: return "none";
    case RemovalReason::BelowFloor: return "below_floor";
    case RemovalReason::BeyondRadius: return "beyond_radius";
    case RemovalReason::NonFinite: return "non_finite";
  }
  return "unknown";
}

struct RigidWorld::Impl {
  struct Body {
    BodyKind kind = BodyKind::Dynamic;
    std::vector<BodyPoseKey> track;
    SE3 T_world_body_initial;
    SE3 T_body_com;  // the shape's centre of mass in the body frame (Bullet's body frame)
    SE3 T_com_body;
    BulletShape shape;
    std::unique_ptr<btRigidBody> rigid;
    RemovalReason removed = RemovalReason::None;
  };
  struct Collider {
    BulletShape shape;
    std::unique_ptr<btCollisionObject> object;
    bool enabled = true;  // in the Bullet world
  };

  explicit Impl(const RigidWorldSettings& s)
      : settings(s),
        clock(s.substep_hz),
        history(static_cast<size_t>(s.history_ns * s.substep_hz / 1'000'000'000 + 2)),
        collision_config(),
        dispatcher(with_multipoint_contacts(collision_config)),
        world(&dispatcher, &broadphase, &solver, &collision_config) {
    world.setGravity(btVector3(static_cast<btScalar>(s.gravity_mps2[0]), static_cast<btScalar>(s.gravity_mps2[1]),
                               static_cast<btScalar>(s.gravity_mps2[2])));
    btContactSolverInfo& solver_info = world.getSolverInfo();
    solver_info.m_numIterations = s.solver_iterations;
    // Every penetration is resolved by the split impulse, which moves bodies apart without adding
    // velocity. Bullet's default (-4 cm) corrects shallower ones with a Baumgarte term in the
    // velocity instead: a ball that sank 7 mm into a box in one substep came back 0.6 m/s too fast,
    // and bounce heights came out 35 to 115 % too high.
    solver_info.m_splitImpulse = 1;
    solver_info.m_splitImpulsePenetrationThreshold = 0;
    solver_info.m_erp2 = kSplitImpulseErp;
    // Two friction directions per contact, fixed when the contact is made (not turned with the
    // sliding velocity every substep): resting boxes do not creep sideways.
    solver_info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS | SOLVER_ENABLE_FRICTION_DIRECTION_CACHING |
                                SOLVER_DISABLE_VELOCITY_DEPENDENT_FRICTION_DIRECTION;
  }

  ~Impl() {
    for (Body& b : bodies)
      if (b.removed == RemovalReason::None) world.removeRigidBody(b.rigid.get());
    for (Collider& c : colliders)
      if (c.enabled) world.removeCollisionObject(c.object.get());
  }

  // Kinematic bodies: where the track puts them at t. `teleport`: also as their previous pose, so
  // the jump carries no velocity (the start, a frozen stretch).
  void place_kinematic(Body& b, int64_t t_ns, bool teleport) {
    const btTransform T = to_bt_transform(pose_on_track(b.track, t_ns, b.T_world_body_initial) * b.T_body_com);
    b.rigid->setWorldTransform(T);
    if (teleport) {
      b.rigid->setInterpolationWorldTransform(T);
      b.rigid->setLinearVelocity(btVector3(0, 0, 0));
      b.rigid->setAngularVelocity(btVector3(0, 0, 0));
    }
  }

  void record(size_t index) {
    const Body& b = bodies[index];
    if (b.removed != RemovalReason::None) return;
    const btRigidBody& r = *b.rigid;
    const btQuaternion q = r.getWorldTransform().getRotation();
    SubstepState s;
    s.position = from_bt_vector(r.getWorldTransform().getOrigin());
    s.quaternion = {q.x(), q.y(), q.z(), q.w()};
    s.linear_velocity = from_bt_vector(r.getLinearVelocity());
    s.angular_velocity = from_bt_vector(r.getAngularVelocity());
    history.record(index, s);
  }

  void snapshot(int64_t t_ns) {
    history.begin_snapshot(t_ns);
    for (size_t i = 0; i < bodies.size(); ++i) record(i);
  }

  // After a substep: a dynamic body outside the world's bounds, or with a non-finite state, leaves.
  size_t remove_escaped() {
    size_t removed = 0;
    for (Body& b : bodies) {
      if (b.removed != RemovalReason::None || b.kind != BodyKind::Dynamic) continue;
      const Vec3 p = from_bt_vector(b.rigid->getCenterOfMassPosition());
      const Vec3 v = from_bt_vector(b.rigid->getLinearVelocity());
      const Vec3 w = from_bt_vector(b.rigid->getAngularVelocity());
      RemovalReason why = RemovalReason::None;
      if (!rigid_state_finite(p) || !rigid_state_finite(v) || !rigid_state_finite(w)) why = RemovalReason::NonFinite;
      else if (p[2] < settings.floor_limit_z_m) why = RemovalReason::BelowFloor;
      else if (norm(p) > settings.world_radius_m) why = RemovalReason::BeyondRadius;
      if (why == RemovalReason::None) continue;
      world.removeRigidBody(b.rigid.get());
      b.removed = why;
      ++removed;
      if (why == RemovalReason::NonFinite) ++stats.removed_non_finite;
      else if (why == RemovalReason::BelowFloor) ++stats.removed_below_floor;
      else ++stats.removed_beyond_radius;
    }
    return removed;
  }

  size_t step_once() {
    const int64_t next_ns = clock.next_ns();
    for (Body& b : bodies)
      if (b.kind == BodyKind::Kinematic && b.removed == RemovalReason::None) place_kinematic(b, next_ns, false);
    const auto dt = static_cast<btScalar>(clock.step_seconds());
    world.stepSimulation(dt, 0, dt);
    clock.tick();
    ++stats.substeps;
    const size_t removed = remove_escaped();
    snapshot(clock.now_ns());
    return removed;
  }

  void start(int64_t t0_ns) {
    started = true;
    clock.restart(t0_ns);
    for (Body& b : bodies)
      if (b.kind == BodyKind::Kinematic) place_kinematic(b, t0_ns, true);
    snapshot(t0_ns);
  }

  // The rest of a jump too long to simulate: the bodies keep their state, the grid restarts at t.
  void freeze_until(int64_t t_ns, AdvanceResult& result) {
    result.frozen_ns = t_ns - clock.now_ns();
    ++stats.capped_advances;
    stats.frozen_ns += result.frozen_ns;
    clock.restart(t_ns);
    for (Body& b : bodies)
      if (b.kind == BodyKind::Kinematic && b.removed == RemovalReason::None) place_kinematic(b, t_ns, true);
    snapshot(t_ns);
  }

  RigidWorldSettings settings;
  SubstepClock clock;
  SubstepHistory history;
  bool started = false;
  RigidWorldStats stats;
  // Bullet's parts, in construction order (the world last, destroyed first).
  btDefaultCollisionConfiguration collision_config;
  btCollisionDispatcher dispatcher;
  btDbvtBroadphase broadphase;
  BounceSolver solver;
  btDiscreteDynamicsWorld world;
  // Declared after the world: destroyed before it, once ~Impl has taken them out.
  std::vector<Body> bodies;
  std::vector<Collider> colliders;
};

namespace {
const RigidWorldSettings& checked_world_settings(const RigidWorldSettings& s) {
  check_world_settings(s);
  return s;
}

// A static collider: it meets everything but other static ones.
void add_static(btDiscreteDynamicsWorld& world, btCollisionObject* object) {
  world.addCollisionObject(object, btBroadphaseProxy::StaticFilter, btBroadphaseProxy::AllFilter ^ btBroadphaseProxy::StaticFilter);
}
}  // namespace

RigidWorld::RigidWorld(const RigidWorldSettings& settings)
    : impl_(std::make_unique<Impl>(checked_world_settings(settings))) {}

RigidWorld::~RigidWorld() = default;

size_t RigidWorld::add_collider(const ColliderSpec& spec) {
  Impl& w = *impl_;
  const size_t index = w.colliders.size();
  const std::string who = physics_item_label("collider", index, spec.name);
  if (index >= lim::kMaxColliders)
    throw PhysicsError(fmt::format("{}: more than the limit of {} colliders", who, lim::kMaxColliders));
  check_collider_spec(spec, index);
  const size_t triangles = bullet_shape_triangle_count(spec.shape);
  if (w.stats.triangles + triangles > lim::kMaxTrianglesTotal)
    throw PhysicsError(fmt::format("{}: its {} triangles take the world past the limit of {} triangles", who, triangles,
                                   lim::kMaxTrianglesTotal));
  Impl::Collider c;
  c.shape = make_bullet_collider_shape(spec.shape, who);
  c.object = std::make_unique<btCollisionObject>();
  c.object->setCollisionShape(c.shape.shape.get());
  c.object->setContactProcessingThreshold(kContactProcessingThresholdM);
  c.object->setWorldTransform(to_bt_transform(spec.T_world_collider * rigid_translation(c.shape.centre_of_mass)));
  c.object->setRestitution(static_cast<btScalar>(spec.restitution));
  c.object->setFriction(static_cast<btScalar>(spec.friction));
  c.object->setRollingFriction(static_cast<btScalar>(spec.rolling_friction));
  add_static(w.world, c.object.get());
  w.stats.triangles += triangles;
  w.stats.degenerate_triangles += c.shape.degenerate_triangles;
  w.colliders.push_back(std::move(c));
  return index;
}

size_t RigidWorld::add_body(const RigidBodySpec& spec) {
  Impl& w = *impl_;
  const size_t index = w.bodies.size();
  const std::string who = physics_item_label("body", index, spec.name);
  if (index >= lim::kMaxBodies)
    throw PhysicsError(fmt::format("{}: more than the limit of {} bodies", who, lim::kMaxBodies));
  if ((index + 1) * uint64_t{w.history.capacity()} > kMaxHistoryStates)
    throw PhysicsError(fmt::format("{}: {} bodies with {} kept substeps each (history_ns x substep_hz) pass the limit "
                                   "of {} kept states",
                                   who, index + 1, w.history.capacity(), kMaxHistoryStates));
  check_body_spec(spec, index);
  const size_t triangles = bullet_shape_triangle_count(spec.shape);
  if (w.stats.triangles + triangles > lim::kMaxTrianglesTotal)
    throw PhysicsError(fmt::format("{}: its {} triangles take the world past the limit of {} triangles", who, triangles,
                                   lim::kMaxTrianglesTotal));

  Impl::Body b;
  b.kind = spec.kind;
  b.track = spec.track;
  b.T_world_body_initial = spec.T_world_body;
  b.shape = make_bullet_body_shape(spec.shape, who);
  b.T_body_com = spec.T_body_shape * rigid_translation(b.shape.centre_of_mass);
  b.T_com_body = b.T_body_com.inverse();

  const bool dynamic = spec.kind == BodyKind::Dynamic;
  const auto mass = static_cast<btScalar>(dynamic ? spec.mass_kg : 0.0);
  btVector3 inertia(0, 0, 0);
  if (dynamic) b.shape.shape->calculateLocalInertia(mass, inertia);
  btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, b.shape.shape.get(), inertia);
  SE3 T_world_body = spec.T_world_body;
  if (spec.kind == BodyKind::Kinematic && w.started) T_world_body = pose_on_track(spec.track, w.clock.now_ns(), spec.T_world_body);
  info.m_startWorldTransform = to_bt_transform(T_world_body * b.T_body_com);
  info.m_restitution = static_cast<btScalar>(spec.restitution);
  info.m_friction = static_cast<btScalar>(spec.friction);
  info.m_rollingFriction = static_cast<btScalar>(spec.rolling_friction);
  info.m_linearDamping = static_cast<btScalar>(spec.linear_damping);
  info.m_angularDamping = static_cast<btScalar>(spec.angular_damping);
  info.m_linearSleepingThreshold = static_cast<btScalar>(w.settings.sleep_linear_mps);
  info.m_angularSleepingThreshold = static_cast<btScalar>(w.settings.sleep_angular_radps);
  b.rigid = std::make_unique<btRigidBody>(info);
  b.rigid->setContactProcessingThreshold(kContactProcessingThresholdM);
  if (spec.kind == BodyKind::Kinematic) {
    b.rigid->setCollisionFlags(b.rigid->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    b.rigid->setActivationState(DISABLE_DEACTIVATION);
  }
  if (dynamic) {
    const Vec3& v = spec.linear_velocity_mps;
    const Vec3& a = spec.angular_velocity_radps;
    b.rigid->setLinearVelocity(btVector3(static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2])));
    b.rigid->setAngularVelocity(btVector3(static_cast<btScalar>(a[0]), static_cast<btScalar>(a[1]), static_cast<btScalar>(a[2])));
    // Continuous collision once a substep moves the body more than half its smallest size, so a
    // fast throw cannot pass through a thin proxy between two substeps.
    btVector3 lo, hi;
    b.shape.shape->getAabb(btTransform::getIdentity(), lo, hi);
    const btVector3 size = hi - lo;
    const btScalar smallest = std::min(size.x(), std::min(size.y(), size.z()));
    b.rigid->setCcdMotionThreshold(smallest * btScalar(0.5));
    b.rigid->setCcdSweptSphereRadius(smallest * btScalar(0.4));
  }
  w.world.addRigidBody(b.rigid.get());
  w.history.add_body();
  w.stats.triangles += triangles;
  w.stats.degenerate_triangles += b.shape.degenerate_triangles;
  w.bodies.push_back(std::move(b));
  if (w.started) w.record(index);
  return index;
}

void RigidWorld::start(int64_t t0_ns) {
  if (impl_->started) return;
  if (t0_ns > kMaxUsableTimeNs || t0_ns < -kMaxUsableTimeNs) {
    ++impl_->stats.ignored_times;
    return;
  }
  impl_->start(t0_ns);
}

bool RigidWorld::started() const { return impl_->started; }

AdvanceResult RigidWorld::advance_to(int64_t t_ns) {
  Impl& w = *impl_;
  AdvanceResult result;
  if (t_ns > kMaxUsableTimeNs || t_ns < -kMaxUsableTimeNs) {
    ++w.stats.ignored_times;
    result.ignored = true;
    return result;
  }
  if (!w.started) {
    w.start(t_ns);
    return result;
  }
  while (w.clock.now_ns() < t_ns) {
    if (result.substeps == w.settings.max_substeps_per_advance) {
      w.freeze_until(t_ns, result);
      break;
    }
    result.removed += w.step_once();
    ++result.substeps;
  }
  return result;
}

BodySample RigidWorld::sample_at(size_t body, int64_t t_ns) const {
  const Impl& w = *impl_;
  if (body >= w.bodies.size()) throw std::out_of_range(fmt::format("physics: no body {} (the world has {})", body, w.bodies.size()));
  const Impl::Body& b = w.bodies[body];
  BodySample out;
  if (!w.started) {
    out.T_world_body = b.kind == BodyKind::Kinematic ? pose_on_track(b.track, t_ns, b.T_world_body_initial)
                                                     : b.T_world_body_initial;
    out.present = true;
    out.clamped = true;
    return out;
  }
  const InterpolatedState s = w.history.at(body, t_ns);
  out.T_world_body = s.T_world_com * b.T_com_body;
  out.linear_velocity_mps = s.linear_velocity;
  out.angular_velocity_radps = s.angular_velocity;
  out.present = s.present;
  out.clamped = s.clamped;
  return out;
}

RemovalReason RigidWorld::removal(size_t body) const {
  if (body >= impl_->bodies.size()) throw std::out_of_range(fmt::format("physics: no body {}", body));
  return impl_->bodies[body].removed;
}

int64_t RigidWorld::oldest_ns() const { return impl_->history.oldest_ns(); }
int64_t RigidWorld::newest_ns() const { return impl_->history.newest_ns(); }
size_t RigidWorld::body_count() const { return impl_->bodies.size(); }
size_t RigidWorld::collider_count() const { return impl_->colliders.size(); }

void RigidWorld::set_collider_enabled(size_t collider, bool enabled) {
  Impl::Collider& c = impl_->colliders.at(collider);
  if (c.enabled == enabled) return;
  if (enabled)
    add_static(impl_->world, c.object.get());
  else
    impl_->world.removeCollisionObject(c.object.get());
  c.enabled = enabled;
}
const RigidWorldStats& RigidWorld::stats() const { return impl_->stats; }
const RigidWorldSettings& RigidWorld::settings() const { return impl_->settings; }

}  // namespace arpipe
