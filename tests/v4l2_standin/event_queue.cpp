#include "event_queue.h"

#include <algorithm>

namespace arpipe::standin {

bool EventQueue::subscribed(uint32_t type, uint32_t id) const {
  return std::any_of(subscriptions_.begin(), subscriptions_.end(),
                     [&](const Subscription& s) { return s.type == type && s.id == id; });
}

uint32_t EventQueue::flags(uint32_t type, uint32_t id) const {
  for (const Subscription& s : subscriptions_)
    if (s.type == type && s.id == id) return s.flags;
  return 0;
}

void EventQueue::subscribe(uint32_t type, uint32_t id, uint32_t flags) {
  for (Subscription& s : subscriptions_)
    if (s.type == type && s.id == id) {
      s.flags = flags;  // as v4l2_event_subscribe: an existing subscription stays, nothing is re-sent
      return;
    }
  subscriptions_.push_back({type, id, flags});
}

void EventQueue::unsubscribe(uint32_t type, uint32_t id) {
  const auto gone = [&](uint32_t t, uint32_t i) { return type == V4L2_EVENT_ALL || (t == type && i == id); };
  std::erase_if(subscriptions_, [&](const Subscription& s) { return gone(s.type, s.id); });
  std::erase_if(events_, [&](const v4l2_event& e) { return gone(e.type, e.id); });
}

bool EventQueue::queue(const v4l2_event& event) {
  if (!subscribed(event.type, event.id)) return false;
  v4l2_event e = event;
  // One slot per subscription (uvcvideo subscribes with one element): the newer event takes the
  // older one's place at the tail, with the changes of both (v4l2_ctrl_replace).
  const auto old = std::find_if(events_.begin(), events_.end(),
                                [&](const v4l2_event& p) { return p.type == e.type && p.id == e.id; });
  if (old != events_.end()) {
    if (e.type == V4L2_EVENT_CTRL) e.u.ctrl.changes |= old->u.ctrl.changes;
    events_.erase(old);
  }
  e.sequence = sequence_++;
  events_.push_back(e);
  return true;
}

bool EventQueue::dequeue(v4l2_event& out) {
  if (events_.empty()) return false;
  out = events_.front();
  events_.pop_front();
  out.pending = uint32_t(events_.size());
  return true;
}

}  // namespace arpipe::standin
