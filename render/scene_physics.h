// The rigid-body world of one config (core/physics): the objects with a physics kind as bodies,
// the proxies with the "collide" role and the ground as colliders, stepped on the frames' exposure
// timestamps so that a replay gives the same trajectory every time and motion blur follows it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/config/config.h"
#include "core/physics/rigid_world.h"
#include "render/uploaded_objects.h"

namespace arpipe {

class ScenePhysics {
 public:
  // Checks every spec now (a ConfigError naming render.objects[i].physics or render.proxies[i] and
  // the field); the world is built at the first frame.
  ScenePhysics(const Config& config, const LoadedMeshes& meshes);
  ~ScenePhysics();

  bool empty() const { return bodies_.empty(); }  // no object moves: nothing to simulate
  // Simulates up to end_ns (the frame's last row's exposure end). The first frame starts the world
  // at its exposure start; a frame that starts before the previous one did (a replay from its
  // beginning again) builds it afresh there, so the same frames give the same trajectory.
  void advance(int64_t exposure_start_ns, int64_t end_ns);
  // The panorama viewpoint the next frames show (FrameMetadata::viewpoint): a proxy of another
  // viewpoint (render.proxies.viewpoint) stops nothing until the view comes back. Frames without
  // one: every collider.
  void set_viewpoint(const std::optional<int>& viewpoint);
  // The object's state at t; nullopt for an object without physics or before the first advance.
  std::optional<BodySample> sample(size_t object_index, int64_t t_ns) const;
  const RigidWorldStats* stats() const { return world_ ? &world_->stats() : nullptr; }
  int64_t restarts() const { return restarts_; }

 private:
  struct Body {
    size_t object_index = 0;
    RigidBodySpec spec;                // track times relative to the start
  };
  void build(int64_t t0_ns);

  RigidWorldSettings settings_;
  std::vector<ColliderSpec> colliders_;
  std::vector<int> collider_viewpoint_;  // per collider: its proxy's viewpoint; -1 every one
  std::optional<int> viewpoint_;
  std::vector<Body> bodies_;
  std::vector<std::optional<size_t>> body_of_object_;  // per render.objects entry
  std::unique_ptr<RigidWorld> world_;
  int64_t start_ns_ = 0;
  int64_t last_start_ns_ = 0;
  int64_t restarts_ = 0;
};

}  // namespace arpipe
