// The process-wide state of the stand-in: the served nodes (devices and loopback pairs), the tracked file descriptors (a
// lock-free table for the interposer's fast path) and the one lock and wake-up the devices share.
#pragma once

#include <poll.h>
#include <sys/types.h>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "device_model.h"

namespace arpipe::standin {

inline constexpr int kMaxTrackedFd = 1 << 16;

// True when fd is one of ours; safe and cheap from any thread, before any constructor has run.
bool is_tracked(int fd);
// True while some configuration is loaded (so open() has paths to look at).
bool is_serving();
// The served path that (dirfd, path) names, following the last component's symlinks, or "" (cheap
// while nothing is served). Never calls an interposed function, so stat() may use it.
std::string served_at(int dirfd, const char* path);
// The served path that (dirfd, path) names itself (no symlink followed: lstat), or "".
std::string served_exactly_at(int dirfd, const char* path);

// What stat() says of a served node: a character device of the video4linux major.
inline constexpr unsigned kVideoMajor = 81;
struct NodeIdentity {
  unsigned minor = 0;
  int64_t loaded_at_ns = 0;  // CLOCK_REALTIME of the load: the node's times
};
// The identity of a served path or a tracked fd; false when it is not one.
bool identity_of_path(const std::string& served, NodeIdentity& out);
bool identity_of_fd(int fd, NodeIdentity& out);
// The served path whose node has this minor, or "".
std::string served_path_of_minor(unsigned minor);

class Registry {
 public:
  static Registry& get();  // never destroyed: libc calls may arrive during exit

  int load(const char* config_path, std::string& error);
  void unload();
  int stats(const char* device_path, struct ::arpipe_v4l2_standin_stats& out);

  // The served device path that `path` names (directly or by a chain of symlinks), or "".
  std::string served_path(const std::string& normal_path);
  // Opens a served path: a tracked fd, or -1 with errno (ENOENT while unplugged).
  int open(const std::string& served, int flags);
  // Untracks fd if it is ours (before the real close).
  void close(int fd);
  // newfd (a real dup of the tracked oldfd's eventfd) shares oldfd's open file, as dup(2) shares
  // the file description. Call with newfd already made; a tracked newfd that dup2 replaced is closed first.
  void dup(int oldfd, int newfd);
  // -1 with errno set, or the ioctl's result; `handled` false when fd is not ours after all.
  int ioctl(int fd, unsigned long request, void* arg, bool& handled);
  void* mmap(int fd, void* addr, size_t length, int prot, int flags, int64_t offset, bool& handled);
  using RealPoll = int (*)(pollfd*, nfds_t, int);
  int poll(pollfd* fds, nfds_t nfds, int timeout_ms, RealPoll real_poll);

 private:
  friend bool identity_of_path(const std::string& served, NodeIdentity& out);
  friend std::string served_path_of_minor(unsigned minor);
  Registry() = default;
  std::shared_ptr<Node> find_device(const std::string& path) const;
  // Makes each open file's eventfd readable exactly while poll() would report something for it
  // (a done buffer, an event, an error), so select() and epoll on the descriptor itself work.
  void sync_readiness();
  // The frame clock: a thread (started at the first open) that lets frames fall due on time and
  // syncs readiness, so a host sleeping in epoll_wait() wakes for them.
  void start_clock();
  void run_clock();
  void fork_prepare();
  void fork_parent();
  void fork_child();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::shared_ptr<Node>> devices_;
  std::unordered_map<int, std::shared_ptr<OpenFile>> files_;
  // The served paths, read by open() without the device lock (a recording's own files are
  // opened while it is held).
  std::mutex paths_mutex_;
  std::vector<std::string> paths_;
  std::vector<NodeIdentity> identities_;  // of paths_, index for index
  bool clock_running_ = false;
};

}  // namespace arpipe::standin
