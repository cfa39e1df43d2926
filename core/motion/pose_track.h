// The timed camera poses of the most recent tracked frames, bounded, from which the motion stage
// takes each frame's neighbours.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>

#include "core/geometry/se3_interpolation.h"

namespace arpipe {

class PoseTrack {
 public:
  struct Entry {
    uint64_t frame = 0;  // FrameContext::input_index
    TimedPose pose;
  };

  // capacity: entries kept (the oldest go first). max_gap_ns: a neighbour further away in time
  // than this is not used (the motion across a longer gap says little about one exposure).
  explicit PoseTrack(size_t capacity = 8, int64_t max_gap_ns = 100'000'000);

  void set_max_gap_ns(int64_t max_gap_ns) { max_gap_ns_ = max_gap_ns; }
  int64_t max_gap_ns() const { return max_gap_ns_; }

  // Adds a tracked frame's pose, in frame order (a frame already held is replaced). A pose whose
  // time contradicts the frame order (a restarted stream) clears the rest.
  void add(uint64_t frame, const TimedPose& pose);
  // Forgets everything (a new anchor, a reconfiguration).
  void clear() { entries_.clear(); }

  bool contains(uint64_t frame) const { return find(frame) != nullptr; }
  const TimedPose* find(uint64_t frame) const;
  // The nearest tracked frame before / after `frame` within max_gap_ns of its pose; nullptr if none.
  const TimedPose* previous(uint64_t frame) const;
  const TimedPose* next(uint64_t frame) const;
  // The same for a frame that is not in the track (a predicted pose at time_ns).
  const TimedPose* before(uint64_t frame, int64_t time_ns) const;
  const TimedPose* after(uint64_t frame, int64_t time_ns) const;
  size_t size() const { return entries_.size(); }

 private:
  const Entry* entry(uint64_t frame) const;
  size_t capacity_;
  int64_t max_gap_ns_;
  std::deque<Entry> entries_;  // increasing frame
};

}  // namespace arpipe
