// RigidWorld: virtual rigid bodies and the static colliders of real geometry (proxies) in one
// Bullet world, stepped in fixed substeps on the frames' timestamps; poses at any recent instant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/geometry/se3.h"
#include "core/physics/collider_spec.h"
#include "core/physics/rigid_body_spec.h"
#include "core/physics/rigid_world_settings.h"

namespace arpipe {

// Why a body is no longer in the world (RigidWorldSettings: floor_limit_z_m, world_radius_m).
enum class RemovalReason { None, BelowFloor, BeyondRadius, NonFinite };
const char* removal_reason_name(RemovalReason reason);  // "none", "below_floor", ...

// A body at one instant. Velocities are the centre of mass's, world frame.
struct BodySample {
  SE3 T_world_body;  // the body (object) frame: what the renderer places the mesh with
  Vec3 linear_velocity_mps{0, 0, 0};
  Vec3 angular_velocity_radps{0, 0, 0};
  bool present = false;  // in the world at t; false once it has left (removed), or before it was added
  bool clamped = false;  // t lay outside [oldest_ns(), newest_ns()]: the nearest end's state
};

struct AdvanceResult {
  int64_t substeps = 0;   // run by this call
  int64_t frozen_ns = 0;  // skipped unsimulated because the call reached max_substeps_per_advance
  size_t removed = 0;     // bodies that left the world during this call
  bool ignored = false;   // the time was outside the usable range (|t| > 2^62 ns); nothing changed
};

struct RigidWorldStats {
  int64_t substeps = 0;
  int64_t capped_advances = 0;  // advances that hit max_substeps_per_advance and froze the rest
  int64_t frozen_ns = 0;        // total time skipped that way
  int64_t ignored_times = 0;    // advance_to calls with an unusable time
  size_t removed_below_floor = 0;
  size_t removed_beyond_radius = 0;
  size_t removed_non_finite = 0;
  size_t triangles = 0;             // in all triangle shapes
  size_t degenerate_triangles = 0;  // skipped while building them
};

// Use: add the colliders and bodies (from the config), then per frame advance_to() the end of the
// frame's exposure (plus readout) and ask sample_at()/pose_at() for every instant the renderer
// needs (the blur samples, the rolling-shutter rows). Same specs and same advance times give
// bit-identical states; the states do not depend on how the time is chunked into advances (while
// no advance hits max_substeps_per_advance). Not thread-safe: one thread owns a world.
class RigidWorld {
 public:
  explicit RigidWorld(const RigidWorldSettings& settings = {});  // PhysicsError on bad settings
  ~RigidWorld();
  RigidWorld(const RigidWorld&) = delete;
  RigidWorld& operator=(const RigidWorld&) = delete;

  // Each returns the new item's index (0, 1, ... in the order added) or throws PhysicsError naming
  // it ("body 2 (\"ball\"): mass_kg: ..."); a refused item leaves the world as it was. A body added
  // after the start enters at the newest substep, at its initial pose and velocity.
  size_t add_collider(const ColliderSpec& spec);
  size_t add_body(const RigidBodySpec& spec);

  // The first substep's time; the first advance_to starts the world at its time if this was not called.
  void start(int64_t t0_ns);
  bool started() const;
  // Runs every substep up to the first at or after t (so that sample_at answers up to t). Earlier
  // or equal times do nothing. Never throws a PhysicsError: a body that leaves the world is
  // removed and counted, an unusable time is ignored and counted.
  AdvanceResult advance_to(int64_t t_ns);

  // The state at t, interpolated between the kept substeps around it. Before the start: the
  // initial pose (present, clamped). Throws std::out_of_range for an index add_body never returned.
  BodySample sample_at(size_t body, int64_t t_ns) const;
  SE3 pose_at(size_t body, int64_t t_ns) const { return sample_at(body, t_ns).T_world_body; }
  RemovalReason removal(size_t body) const;

  int64_t oldest_ns() const;  // the kept span of substeps; both 0 before the start
  int64_t newest_ns() const;
  size_t body_count() const;
  size_t collider_count() const;
  // Takes a collider out of the world (false) or puts it back (true) from the next substep on: a
  // proxy of a panorama viewpoint the view has left stops nothing. Every collider starts enabled.
  // Throws std::out_of_range for an index add_collider never returned.
  void set_collider_enabled(size_t collider, bool enabled);
  const RigidWorldStats& stats() const;
  const RigidWorldSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
