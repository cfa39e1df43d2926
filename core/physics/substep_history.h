// The last substep states of every body (a ring of snapshots), and the state at any instant between
// two kept snapshots: centre of mass linear, orientation by slerp, velocities linear.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/geometry/se3.h"

namespace arpipe {

// A body's centre-of-mass frame and velocities at one substep, world frame.
struct SubstepState {
  Vec3 position{0, 0, 0};
  std::array<double, 4> quaternion{0, 0, 0, 1};  // x, y, z, w; unit
  Vec3 linear_velocity{0, 0, 0};
  Vec3 angular_velocity{0, 0, 0};
};

struct InterpolatedState {
  SE3 T_world_com;
  Vec3 linear_velocity{0, 0, 0};
  Vec3 angular_velocity{0, 0, 0};
  bool present = false;  // the body was in the world at t (added by then, not yet removed)
  bool clamped = false;  // t lay outside the kept span: the nearest kept snapshot's state
};

class SubstepHistory {
 public:
  explicit SubstepHistory(size_t capacity);  // snapshots kept, at least 2

  size_t capacity() const { return times_.size(); }
  void add_body();  // the next body index; absent from every snapshot so far
  size_t body_count() const { return states_.size(); }

  // Opens a snapshot at t (later than the newest); bodies not recorded into it are absent there.
  void begin_snapshot(int64_t t_ns);
  void record(size_t body, const SubstepState& state);  // into the newest snapshot
  // The newest snapshot's state of a body, or nullptr when it is absent there.
  const SubstepState* newest(size_t body) const;

  bool empty() const { return count_ == 0; }
  int64_t oldest_ns() const;  // of the oldest kept snapshot; 0 when empty
  int64_t newest_ns() const;
  InterpolatedState at(size_t body, int64_t t_ns) const;

 private:
  const SubstepState* state(size_t body, uint64_t snapshot) const;
  int64_t time_of(uint64_t snapshot) const { return times_[snapshot % times_.size()]; }
  uint64_t first_kept() const { return count_ > times_.size() ? count_ - times_.size() : 0; }

  std::vector<int64_t> times_;  // ring, by snapshot number modulo capacity
  std::vector<std::vector<SubstepState>> states_;  // per body, same ring
  std::vector<std::vector<uint64_t>> stamps_;     // per body: snapshot number + 1 a slot holds; 0: none
  uint64_t count_ = 0;                            // snapshots begun so far
};

// The rotation of a unit quaternion (x, y, z, w), normalised first.
Mat3 rotation_from_quaternion(const std::array<double, 4>& q);

}  // namespace arpipe
