// One file handle's V4L2 event subscriptions and pending events, with the kernel's rules: one
// slot per subscribed control, a newer event replaces a pending one (changes merged), sequence counts all.
#pragma once

#include <linux/videodev2.h>

#include <cstdint>
#include <deque>
#include <vector>

namespace arpipe::standin {

class EventQueue {
 public:
  bool subscribed(uint32_t type, uint32_t id) const;
  uint32_t flags(uint32_t type, uint32_t id) const;  // the subscription's V4L2_EVENT_SUB_FL_*
  void subscribe(uint32_t type, uint32_t id, uint32_t flags);
  // type V4L2_EVENT_ALL drops every subscription; pending events of a dropped one go too.
  void unsubscribe(uint32_t type, uint32_t id);
  // Queues an event for a subscription (ignored without one); false when it was not subscribed.
  bool queue(const v4l2_event& event);
  bool pending() const { return !events_.empty(); }
  // The oldest event with `pending` set to how many remain; false when none.
  bool dequeue(v4l2_event& out);

 private:
  struct Subscription {
    uint32_t type, id, flags;
  };
  std::vector<Subscription> subscriptions_;
  std::deque<v4l2_event> events_;
  uint32_t sequence_ = 0;
};

}  // namespace arpipe::standin
