// Substep history: a binary search over the kept snapshot times, then linear interpolation of the
// centre of mass (exact for constant velocity; for free fall the chord of the parabola is off by at
// most g dt^2 / 8 at mid-step) and slerp of the orientation.
#include "core/physics/substep_history.h"

#include <cmath>

#include "core/geometry/se3_interpolation.h"

namespace arpipe {

namespace {

SE3 substep_com_pose(const SubstepState& s) { return SE3(rotation_from_quaternion(s.quaternion), s.position); }

Vec3 lerp_substep_vector(const Vec3& a, const Vec3& b, double s) { return a + s * (b - a); }

InterpolatedState substep_state_as_is(const SubstepState& s) {
  InterpolatedState out;
  out.T_world_com = substep_com_pose(s);
  out.linear_velocity = s.linear_velocity;
  out.angular_velocity = s.angular_velocity;
  out.present = true;
  return out;
}

}  // namespace

Mat3 rotation_from_quaternion(const std::array<double, 4>& quat) {
  const double n = std::sqrt(quat[0] * quat[0] + quat[1] * quat[1] + quat[2] * quat[2] + quat[3] * quat[3]);
  if (!(n > 0)) return identity3();
  const double x = quat[0] / n, y = quat[1] / n, z = quat[2] / n, w = quat[3] / n;
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
           {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
           {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

SubstepHistory::SubstepHistory(size_t capacity) : times_(capacity < 2 ? 2 : capacity, 0) {}

void SubstepHistory::add_body() {
  states_.emplace_back(times_.size());
  stamps_.emplace_back(times_.size(), 0);
}

void SubstepHistory::begin_snapshot(int64_t t_ns) {
  times_[count_ % times_.size()] = t_ns;
  ++count_;
}

void SubstepHistory::record(size_t body, const SubstepState& s) {
  if (count_ == 0) return;
  const size_t slot = (count_ - 1) % times_.size();
  states_[body][slot] = s;
  stamps_[body][slot] = count_;  // snapshot number count_ - 1, plus one
}

const SubstepState* SubstepHistory::state(size_t body, uint64_t snapshot) const {
  const size_t slot = snapshot % times_.size();
  return stamps_[body][slot] == snapshot + 1 ? &states_[body][slot] : nullptr;
}

const SubstepState* SubstepHistory::newest(size_t body) const {
  return count_ == 0 ? nullptr : state(body, count_ - 1);
}

int64_t SubstepHistory::oldest_ns() const { return count_ == 0 ? 0 : time_of(first_kept()); }
int64_t SubstepHistory::newest_ns() const { return count_ == 0 ? 0 : time_of(count_ - 1); }

InterpolatedState SubstepHistory::at(size_t body, int64_t t_ns) const {
  InterpolatedState out;
  if (count_ == 0 || body >= states_.size()) return out;
  const uint64_t first = first_kept(), last = count_ - 1;
  if (t_ns <= time_of(first) || t_ns >= time_of(last)) {
    const uint64_t n = t_ns <= time_of(first) ? first : last;
    if (const SubstepState* s = state(body, n)) out = substep_state_as_is(*s);
    out.clamped = t_ns != time_of(n);
    return out;
  }
  // The last snapshot at or before t: time_of(lo) <= t < time_of(hi).
  uint64_t lo = first, hi = last;
  while (hi - lo > 1) {
    const uint64_t mid = lo + (hi - lo) / 2;
    (time_of(mid) <= t_ns ? lo : hi) = mid;
  }
  const SubstepState* a = state(body, lo);
  const SubstepState* b = state(body, hi);
  if (a && t_ns == time_of(lo)) return substep_state_as_is(*a);
  if (!a || !b) {
    // Added or removed between the two snapshots: not in the world at t (the pose given is the
    // nearest one it had, for reports).
    if (a || b) out = substep_state_as_is(a ? *a : *b);
    out.present = false;
    return out;
  }
  const double s = time_fraction(time_of(lo), time_of(hi), t_ns);
  out.T_world_com = substep_com_pose(*a).interpolate(substep_com_pose(*b), s);
  out.linear_velocity = lerp_substep_vector(a->linear_velocity, b->linear_velocity, s);
  out.angular_velocity = lerp_substep_vector(a->angular_velocity, b->angular_velocity, s);
  out.present = true;
  return out;
}

}  // namespace arpipe
