#include "standin_registry.h"

#include <fmt/format.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <thread>

#include "loopback_capture.h"
#include "loopback_output.h"

namespace arpipe::standin {

namespace {

std::atomic<bool> g_tracked[kMaxTrackedFd];
std::atomic<uint16_t> g_minor[kMaxTrackedFd];  // of each tracked fd's node (fstat without the lock)
std::atomic<bool> g_serving{false};
std::atomic<int64_t> g_loaded_at{0};

// Everything poll() can report on a node: the eventfd is readable while any of it holds.
constexpr short kAnyEvent = POLLIN | POLLRDNORM | POLLOUT | POLLWRNORM | POLLPRI;

int64_t realtime_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// /dev/videoN keeps N as its minor (as the kernel numbers them); other paths get the lowest free
// minor from 64 up, so each node of a configuration has its own.
std::vector<NodeIdentity> assign_identities(const std::vector<std::string>& paths) {
  std::vector<NodeIdentity> out(paths.size());
  std::vector<bool> taken(256 + paths.size(), false);
  std::vector<bool> numbered(paths.size(), false);
  const int64_t loaded_at = realtime_ns();
  for (size_t i = 0; i < paths.size(); ++i) {
    out[i].loaded_at_ns = loaded_at;
    const std::string_view p = paths[i];
    constexpr std::string_view prefix = "/dev/video";
    if (!p.starts_with(prefix) || p.size() == prefix.size() || p.size() > prefix.size() + 3) continue;
    unsigned n = 0;
    bool digits = true;
    for (const char c : p.substr(prefix.size())) {
      digits = digits && c >= '0' && c <= '9';
      n = n * 10 + unsigned(c - '0');
    }
    if (!digits || n > 255 || taken[n]) continue;
    out[i].minor = n;
    taken[n] = numbered[i] = true;
  }
  unsigned next = 64;
  for (size_t i = 0; i < paths.size(); ++i) {
    if (numbered[i]) continue;
    while (taken[next]) ++next;
    out[i].minor = next;
    taken[next] = true;
  }
  return out;
}

ssize_t raw_readlink(const char* path, char* buf, size_t size) { return ::syscall(SYS_readlinkat, AT_FDCWD, path, buf, size); }

// With real descriptors in the same poll() the device lock cannot wake the sleeper, so it sleeps
// at most this long between looks at the served devices (another thread may have queued a buffer).
constexpr int64_t kMixedPollSliceNs = 5000000;

void wait_on(std::condition_variable& cv, std::unique_lock<std::mutex>& lock, int64_t deadline_ns) {
  if (deadline_ns == kNever) {
    cv.wait(lock);
    return;
  }
  const int64_t left = deadline_ns - monotonic_ns();
  if (left > 0) cv.wait_for(lock, std::chrono::nanoseconds(left));
}

}  // namespace

bool is_tracked(int fd) { return fd >= 0 && fd < kMaxTrackedFd && g_tracked[fd].load(std::memory_order_acquire); }
bool is_serving() { return g_serving.load(std::memory_order_acquire); }

namespace {
// The absolute form of (dirfd, path), or "" when it cannot be a served path.
std::string absolute_at(int dirfd, const char* path) {
  if (!is_serving() || path == nullptr || *path == '\0') return "";
  std::string full = path;
  if (full[0] != '/' && dirfd != AT_FDCWD) {
    char link[64], dir[4096];
    std::snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
    const ssize_t n = raw_readlink(link, dir, sizeof dir - 1);
    if (n <= 0) return "";
    dir[n] = '\0';
    full = std::string(dir) + "/" + full;
  }
  return normal_device_path(full);
}
}  // namespace

std::string served_at(int dirfd, const char* path) {
  const std::string full = absolute_at(dirfd, path);
  return full.empty() ? "" : Registry::get().served_path(full);
}

std::string served_exactly_at(int dirfd, const char* path) {
  const std::string full = absolute_at(dirfd, path);
  NodeIdentity unused;
  return !full.empty() && identity_of_path(full, unused) ? full : "";
}

bool identity_of_fd(int fd, NodeIdentity& out) {
  if (!is_tracked(fd)) return false;
  out.minor = g_minor[fd].load(std::memory_order_acquire);
  out.loaded_at_ns = g_loaded_at.load(std::memory_order_acquire);
  return true;
}

Registry& Registry::get() {
  static Registry* registry = new Registry;
  return *registry;
}

int Registry::load(const char* config_path, std::string& error) {
  std::vector<std::shared_ptr<Node>> devices;
  try {
    // Recordings are opened without any lock held: their files go through our open().
    StandinConfig config = load_standin_config(config_path);
    for (DeviceConfig& device : config.devices) devices.push_back(std::make_shared<Device>(std::move(device)));
    for (const LoopbackConfig& loopback : config.loopbacks) {
      std::error_code ec;
      std::filesystem::create_directories(loopback.spool, ec);
      if (ec || !std::filesystem::is_directory(loopback.spool))
        throw StandinConfigError(fmt::format("{}: cannot make the spool directory \"{}\": {}", loopback.place,
                                             loopback.spool.string(), ec ? ec.message() : "not a directory"));
      devices.push_back(std::make_shared<LoopbackOutput>(loopback));
      devices.push_back(std::make_shared<LoopbackCapture>(loopback));
    }
  } catch (const std::exception& e) {
    error = e.what();
    return -1;
  }
  std::lock_guard lock(mutex_);
  for (const auto& d : devices_)
    if (d->open()) {
      error = fmt::format("{}: busy: {} is still open", config_path, d->path());
      return -1;
    }
  devices_ = std::move(devices);
  std::lock_guard paths_lock(paths_mutex_);
  paths_.clear();
  for (const auto& d : devices_) paths_.push_back(d->path());
  identities_ = assign_identities(paths_);
  if (!identities_.empty()) g_loaded_at.store(identities_[0].loaded_at_ns, std::memory_order_release);
  g_serving.store(!paths_.empty(), std::memory_order_release);
  return 0;
}

void Registry::unload() {
  std::lock_guard lock(mutex_);
  for (const auto& d : devices_) d->disconnect_all();
  devices_.clear();
  sync_readiness();  // the dead files are readable (POLLERR|POLLHUP)
  std::lock_guard paths_lock(paths_mutex_);
  paths_.clear();
  identities_.clear();
  g_serving.store(false, std::memory_order_release);
  wake_.notify_all();
}

std::string served_path_of_minor(unsigned minor) {
  Registry& r = Registry::get();
  std::lock_guard lock(r.paths_mutex_);
  for (size_t i = 0; i < r.paths_.size(); ++i)
    if (r.identities_[i].minor == minor) return r.paths_[i];
  return "";
}

bool identity_of_path(const std::string& served, NodeIdentity& out) {
  Registry& r = Registry::get();
  std::lock_guard lock(r.paths_mutex_);
  for (size_t i = 0; i < r.paths_.size(); ++i)
    if (r.paths_[i] == served) {
      out = r.identities_[i];
      return true;
    }
  return false;
}

std::shared_ptr<Node> Registry::find_device(const std::string& path) const {
  for (const auto& d : devices_)
    if (d->path() == path) return d;
  return nullptr;
}

int Registry::stats(const char* device_path, struct ::arpipe_v4l2_standin_stats& out) {
  if (device_path == nullptr) {
    errno = ENOENT;
    return -1;
  }
  std::lock_guard lock(mutex_);
  const auto d = find_device(normal_device_path(device_path));
  if (!d) {
    errno = ENOENT;
    return -1;
  }
  out = d->stats;
  return 0;
}

std::string Registry::served_path(const std::string& normal_path) {
  std::string p = normal_path;
  // Follows the chain of symlinks of the last component (e.g. /dev/v4l/by-id/... -> ../../videoN).
  for (int hop = 0; hop < 40; ++hop) {
    {
      std::lock_guard lock(paths_mutex_);
      if (std::find(paths_.begin(), paths_.end(), p) != paths_.end()) return p;
    }
    char target[4096];  // readlink fails (EINVAL) on a path that is not a symlink
    const ssize_t n = raw_readlink(p.c_str(), target, sizeof target - 1);
    if (n <= 0) return "";
    target[n] = '\0';
    std::filesystem::path next(target);
    if (next.is_relative()) next = std::filesystem::path(p).parent_path() / next;
    p = normal_device_path(next.string());
  }
  return "";
}

int Registry::open(const std::string& served, int flags) {
  std::lock_guard lock(mutex_);
  const auto d = find_device(served);
  const int64_t now = monotonic_ns();
  if (!d || !d->present(now)) {
    errno = ENOENT;  // unplugged: the node is gone
    return -1;
  }
  d->advance(now);
  const int fd = ::eventfd(0, ((flags & O_NONBLOCK) ? EFD_NONBLOCK : 0) | ((flags & O_CLOEXEC) ? EFD_CLOEXEC : 0));
  if (fd < 0) return -1;
  if (fd >= kMaxTrackedFd) {
    ::close(fd);
    errno = EMFILE;
    return -1;
  }
  auto file = std::make_shared<OpenFile>();
  file->fd = fd;
  file->device = d;
  d->attach(*file);
  files_[fd] = file;
  NodeIdentity identity;
  {
    std::lock_guard paths_lock(paths_mutex_);
    for (size_t i = 0; i < paths_.size(); ++i)
      if (paths_[i] == served) identity = identities_[i];
  }
  g_minor[fd].store(uint16_t(identity.minor), std::memory_order_release);
  g_tracked[fd].store(true, std::memory_order_release);
  sync_readiness();
  start_clock();
  return fd;
}

void Registry::close(int fd) {
  std::lock_guard lock(mutex_);
  const auto it = files_.find(fd);
  if (it == files_.end()) return;
  const std::shared_ptr<OpenFile> file = it->second;
  files_.erase(it);
  g_tracked[fd].store(false, std::memory_order_release);
  if (--file->descriptors > 0) {  // a dup still refers to the open file: it stays
    if (file->fd == fd)
      for (const auto& [other, f] : files_)
        if (f == file) file->fd = other;
    return;
  }
  file->device->detach(*file);
  file->dead = true;  // a thread still blocked on it wakes and leaves
  sync_readiness();    // closing the owner may have stopped a stream other handles watch
  wake_.notify_all();
}

void Registry::dup(int oldfd, int newfd) {
  std::lock_guard lock(mutex_);
  const auto it = files_.find(oldfd);
  if (it == files_.end() || newfd < 0 || newfd == oldfd) return;
  if (newfd >= kMaxTrackedFd) return;  // cannot be tracked: it stays a plain eventfd
  const std::shared_ptr<OpenFile> file = it->second;
  ++file->descriptors;
  files_[newfd] = file;
  g_minor[newfd].store(g_minor[oldfd].load(std::memory_order_acquire), std::memory_order_release);
  g_tracked[newfd].store(true, std::memory_order_release);
}

void Registry::sync_readiness() {
  for (const auto& [fd, file] : files_) {
    if (fd != file->fd) continue;  // a dup shares the eventfd (and its counter)
    const bool ready = file->dead || file->device->poll_events(*file, kAnyEvent) != 0;
    if (ready == file->signalled) continue;
    uint64_t value = 1;
    // Raw system calls: read() is interposed, and the counter must not be anyone else's business.
    const long r = ready ? ::syscall(SYS_write, fd, &value, sizeof value) : ::syscall(SYS_read, fd, &value, sizeof value);
    if (r == long(sizeof value)) file->signalled = ready;
  }
}

void Registry::start_clock() {
  if (clock_running_) return;
  clock_running_ = true;
  static std::once_flag atfork;
  std::call_once(atfork, [] {
    ::pthread_atfork([] { Registry::get().fork_prepare(); }, [] { Registry::get().fork_parent(); },
                     [] { Registry::get().fork_child(); });
  });
  std::thread([this] { run_clock(); }).detach();
}

void Registry::run_clock() {
  std::unique_lock lock(mutex_);
  while (clock_running_) {
    const int64_t now = monotonic_ns();
    int64_t wake = kNever;
    for (const auto& d : devices_) {
      if (!d->open()) continue;
      d->present(now);
      d->advance(now);
      wake = std::min(wake, d->next_wake(now));
    }
    sync_readiness();
    wake_.notify_all();  // a DQBUF or poll() sleeping on the lock looks again
    wait_on(wake_, lock, wake);
  }
}

// fork() copies the state but not the clock's thread: the child starts its own at its next open,
// and neither lock is held across the fork by a thread the child does not have.
void Registry::fork_prepare() {
  mutex_.lock();
  paths_mutex_.lock();
}
void Registry::fork_parent() {
  paths_mutex_.unlock();
  mutex_.unlock();
}
void Registry::fork_child() {
  paths_mutex_.unlock();
  mutex_.unlock();
  clock_running_ = false;  // the next ioctl starts the child's own
}

int Registry::ioctl(int fd, unsigned long request, void* arg, bool& handled) {
  std::unique_lock lock(mutex_);
  const auto it = files_.find(fd);
  handled = it != files_.end();
  if (!handled) return -1;
  const std::shared_ptr<OpenFile> file = it->second;
  Node& d = *file->device;
  const int64_t now = monotonic_ns();
  d.present(now);
  d.advance(now);  // may unplug the device
  if (file->dead) {
    errno = ENODEV;  // the v4l2 core for an unregistered video device
    return -1;
  }
  const Waiter wait = [&](int64_t deadline) { wait_on(wake_, lock, deadline); };
  start_clock();  // after a fork() the child has none yet
  const int err = d.ioctl(*file, request, arg, wait);
  sync_readiness();
  wake_.notify_all();
  if (err != 0) {
    errno = err;
    return -1;
  }
  return 0;
}

void* Registry::mmap(int fd, void* addr, size_t length, int prot, int flags, int64_t offset, bool& handled) {
  std::lock_guard lock(mutex_);
  const auto it = files_.find(fd);
  handled = it != files_.end();
  if (!handled) return MAP_FAILED;
  const std::shared_ptr<OpenFile> file = it->second;
  file->device->advance(monotonic_ns());
  if (file->dead) {
    errno = ENODEV;
    return MAP_FAILED;
  }
  void* p = file->device->mmap(addr, length, prot, flags, offset);
  sync_readiness();
  return p;
}

int Registry::poll(pollfd* fds, nfds_t nfds, int timeout_ms, RealPoll real_poll) {
  const int64_t start = monotonic_ns();
  const int64_t deadline = timeout_ms < 0 ? kNever : start + int64_t(timeout_ms) * 1000000;
  bool any_real = false;
  for (nfds_t i = 0; i < nfds; ++i)
    if (fds[i].fd >= 0 && !is_tracked(fds[i].fd)) any_real = true;
  std::vector<pollfd> real;
  if (any_real) real.assign(fds, fds + nfds);

  // Looks at the tracked entries: sets their revents, returns how many are ready and when a
  // served device may next change.
  const auto look = [&](int64_t now, int64_t& wake) {
    int ready = 0;
    wake = kNever;
    for (nfds_t i = 0; i < nfds; ++i) {
      if (fds[i].fd < 0 || !is_tracked(fds[i].fd)) continue;
      const auto it = files_.find(fds[i].fd);
      fds[i].revents = 0;
      if (it == files_.end()) {
        fds[i].revents = POLLNVAL;
        ++ready;
        continue;
      }
      const OpenFile& file = *it->second;
      Node& d = *file.device;
      d.present(now);
      if (!file.dead) {
        d.advance(now);
        wake = std::min(wake, d.next_wake(now));
      }
      fds[i].revents = d.poll_events(file, fds[i].events);
      if (fds[i].revents != 0) ++ready;
    }
    sync_readiness();
    return ready;
  };

  std::unique_lock lock(mutex_);
  for (;;) {
    int64_t now = monotonic_ns(), wake = kNever;
    int ready = look(now, wake);
    if (!any_real) {
      if (ready > 0 || now >= deadline) return ready;
      wait_on(wake_, lock, std::min(deadline, wake));
      continue;
    }
    // Real descriptors too: the real poll() on them (ours masked out), its sleep cut to when a
    // served device may change.
    const int64_t until = ready > 0 ? now : std::min({deadline, wake, now + kMixedPollSliceNs});
    const int slice_ms = until <= now ? 0 : int((until - now + 999999) / 1000000);
    for (nfds_t i = 0; i < nfds; ++i) {
      real[i] = fds[i];
      if (is_tracked(fds[i].fd)) real[i].fd = -1;
    }
    lock.unlock();
    const int n = real_poll(real.data(), nfds, slice_ms);
    const int saved_errno = errno;
    lock.lock();
    if (n < 0) {
      errno = saved_errno;
      return -1;
    }
    now = monotonic_ns();
    if (n > 0 && ready == 0) ready = look(now, wake);  // report served devices that became ready meanwhile
    int real_ready = 0;
    for (nfds_t i = 0; i < nfds; ++i) {
      if (fds[i].fd < 0 || is_tracked(fds[i].fd)) continue;
      fds[i].revents = real[i].revents;
      if (fds[i].revents != 0) ++real_ready;
    }
    if (ready + real_ready > 0 || now >= deadline) return ready + real_ready;
  }
}

}  // namespace arpipe::standin
