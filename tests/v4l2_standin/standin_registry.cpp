#include "standin_registry.h"

#include <fmt/format.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>

#include "loopback_capture.h"
#include "loopback_output.h"

namespace arpipe::standin {

namespace {

std::atomic<bool> g_tracked[kMaxTrackedFd];
std::atomic<bool> g_serving{false};

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
  g_serving.store(!paths_.empty(), std::memory_order_release);
  return 0;
}

void Registry::unload() {
  std::lock_guard lock(mutex_);
  for (const auto& d : devices_) d->disconnect_all();
  devices_.clear();
  std::lock_guard paths_lock(paths_mutex_);
  paths_.clear();
  g_serving.store(false, std::memory_order_release);
  wake_.notify_all();
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
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return "";
    char target[4096];
    const ssize_t n = ::readlink(p.c_str(), target, sizeof target - 1);
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
  g_tracked[fd].store(true, std::memory_order_release);
  return fd;
}

void Registry::close(int fd) {
  std::lock_guard lock(mutex_);
  const auto it = files_.find(fd);
  if (it == files_.end()) return;
  const std::shared_ptr<OpenFile> file = it->second;
  files_.erase(it);
  g_tracked[fd].store(false, std::memory_order_release);
  file->device->detach(*file);
  file->dead = true;  // a thread still blocked on it wakes and leaves
  wake_.notify_all();
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
  const int err = d.ioctl(*file, request, arg, wait);
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
  return file->device->mmap(addr, length, prot, flags, offset);
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
