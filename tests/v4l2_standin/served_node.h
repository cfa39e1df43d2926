// A served device node (a capture device from a recording, or either end of a loopback pair): what
// the registry calls for every open file, ioctl, mmap and poll on one of its paths.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "event_queue.h"
#include "v4l2_standin.h"

namespace arpipe::standin {

inline constexpr int64_t kNever = INT64_MAX;

int64_t monotonic_ns();

class Node;

// An open file description of a served node (one per tracked fd).
struct OpenFile {
  int fd = -1;         // one of its descriptors (dup()s share the file; this one is open)
  int descriptors = 1;  // how many tracked descriptors refer to it (dup, dup2, fcntl(F_DUPFD))
  bool signalled = false;  // the eventfd's counter is non-zero (readable for select/epoll)
  std::shared_ptr<Node> device;
  bool dead = false;  // the device was unplugged or unloaded: ENODEV from now on
  EventQueue events;
};

// Waits (with the registry's lock released) until the deadline (kNever: until woken).
using Waiter = std::function<void(int64_t deadline_ns)>;

// Everything below runs with the registry's lock held.
class Node {
 public:
  virtual ~Node() = default;
  virtual const std::string& path() const = 0;
  // False while unplugged (until the replug time has passed).
  virtual bool present(int64_t now) = 0;
  virtual void attach(OpenFile& file) = 0;
  virtual void detach(OpenFile& file) = 0;  // close(): the owner's close stops streaming and frees the buffers
  virtual bool open() const = 0;
  // Unload: every open file goes dead (ENODEV) and streaming stops.
  virtual void disconnect_all() = 0;
  // Lets everything that is due by `now` happen (frames, faults, events).
  virtual void advance(int64_t now) = 0;
  // When advance() may next have something to do; kNever: only when the host acts.
  virtual int64_t next_wake(int64_t now) const = 0;
  // A V4L2 ioctl: 0 or an errno.
  virtual int ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) = 0;
  virtual short poll_events(const OpenFile& file, short requested) const = 0;
  // mmap of a buffer: the mapping, or MAP_FAILED with errno set.
  virtual void* mmap(void* addr, size_t length, int prot, int flags, int64_t offset) = 0;

  struct ::arpipe_v4l2_standin_stats stats{};
};

// Whether a call on the file may block: follows the descriptor's current O_NONBLOCK (F_SETFL).
bool blocking_file(const OpenFile& file);

}  // namespace arpipe::standin
