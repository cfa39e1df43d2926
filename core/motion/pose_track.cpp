// PoseTrack: a short, ordered history of timed poses.
#include "core/motion/pose_track.h"

#include <iterator>

namespace arpipe {

PoseTrack::PoseTrack(size_t capacity, int64_t max_gap_ns) : capacity_(capacity < 2 ? 2 : capacity), max_gap_ns_(max_gap_ns) {}

void PoseTrack::add(uint64_t frame, const TimedPose& pose) {
  // In frame order, replacing the same frame. Frame numbers and times must increase together;
  // where they do not, the stream restarted (a loop, a new source) and the rest is another run.
  auto at = entries_.begin();
  while (at != entries_.end() && at->frame < frame) ++at;
  if (at != entries_.end() && at->frame == frame) at = entries_.erase(at);
  const bool before_ok = at == entries_.begin() || std::prev(at)->pose.time_ns < pose.time_ns;
  const bool after_ok = at == entries_.end() || at->pose.time_ns > pose.time_ns;
  if (!before_ok || !after_ok) {
    entries_.clear();
    at = entries_.begin();
  }
  entries_.insert(at, {frame, pose});
  while (entries_.size() > capacity_) entries_.pop_front();
}

const PoseTrack::Entry* PoseTrack::entry(uint64_t frame) const {
  for (const Entry& e : entries_)
    if (e.frame == frame) return &e;
  return nullptr;
}

const TimedPose* PoseTrack::find(uint64_t frame) const {
  const Entry* e = entry(frame);
  return e ? &e->pose : nullptr;
}

const TimedPose* PoseTrack::previous(uint64_t frame) const {
  const Entry* self = entry(frame);
  return self ? before(frame, self->pose.time_ns) : nullptr;
}

const TimedPose* PoseTrack::next(uint64_t frame) const {
  const Entry* self = entry(frame);
  return self ? after(frame, self->pose.time_ns) : nullptr;
}

const TimedPose* PoseTrack::before(uint64_t frame, int64_t time_ns) const {
  const Entry* best = nullptr;
  for (const Entry& e : entries_)
    if (e.frame < frame) best = &e;
  if (!best || time_ns - best->pose.time_ns > max_gap_ns_) return nullptr;
  return &best->pose;
}

const TimedPose* PoseTrack::after(uint64_t frame, int64_t time_ns) const {
  for (const Entry& e : entries_)
    if (e.frame > frame) return e.pose.time_ns - time_ns > max_gap_ns_ ? nullptr : &e.pose;
  return nullptr;
}

}  // namespace arpipe
