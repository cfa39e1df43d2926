// What the render stage says about each virtual object of a frame, for results.jsonl and /state:
// where it is (it may move by physics), whether it is still in the world, and how much of it the
// phantom proxies hid, and which.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/vec.h"

namespace arpipe {

struct ObjectReport {
  int index = 0;                 // in render.objects
  Vec3 position_m{0, 0, 0};      // the object's origin in the world at mid-exposure
  bool present = true;           // false once the physics removed it (it left the world)
  bool in_view = false;          // its box reaches into the picture
  // Of the object's own pixels (rays that meet it), the share behind a proxy that occludes, in
  // all and per proxy (by name, the nearest one in front). Measured when in view; 0 otherwise.
  double hidden = 0;
  std::vector<std::pair<std::string, double>> hidden_by;
};

// The scene's animation at the frame (render.proxies[].node of an animated glTF): the time it was
// sampled at (FrameMetadata::source_frame_time_ns) and where each animated proxy stood then.
struct AnimationReport {
  double time_s = 0;
  struct Proxy {
    std::string name;
    Vec3 position_m{0, 0, 0};   // the proxy's origin in the world
    Vec3 rotation_vector{0, 0, 0};
    double scale = 1;
  };
  std::vector<Proxy> proxies;
};

// The rigid-body world's counters (render/scene_physics.h), since the daemon started, for the
// frames of a config with physics: what was simulated and what left the world.
struct PhysicsReport {
  int64_t substeps = 0;
  int64_t restarts = 0;          // a replay that started over built the world again
  int64_t capped_advances = 0;   // frames after a gap longer than render.physics.max_advance_ms
  size_t removed_below_floor = 0;
  size_t removed_beyond_radius = 0;
  size_t removed_non_finite = 0;
};

}  // namespace arpipe
