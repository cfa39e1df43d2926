// select, pselect and ppoll on tracked fds: answered like poll() (the registry's), so that their
// kernel meanings hold: select's readfds see POLLIN|POLLHUP|POLLERR, writefds POLLOUT|POLLERR and
// exceptfds POLLPRI (a pending V4L2 event), which the eventfd alone cannot show. epoll is not
// interposed: it watches the eventfd, which the registry makes readable whenever poll() would
// report anything for the node.
#undef _FORTIFY_SOURCE

#include <poll.h>
#include <signal.h>
#include <sys/select.h>

#include <atomic>
#include <cerrno>
#include <algorithm>
#include <climits>
#include <vector>

#include "next_symbol.h"
#include "standin_registry.h"

using arpipe::standin::is_tracked;
using arpipe::standin::Registry;

namespace {

using SelectFn = int (*)(int, fd_set*, fd_set*, fd_set*, timeval*);
using PselectFn = int (*)(int, fd_set*, fd_set*, fd_set*, const timespec*, const sigset_t*);
using PpollFn = int (*)(pollfd*, nfds_t, const timespec*, const sigset_t*);
using PollFn = int (*)(pollfd*, nfds_t, int);
using PpollChkFn = int (*)(pollfd*, nfds_t, const timespec*, const sigset_t*, size_t);

int real_poll(pollfd* fds, nfds_t nfds, int timeout) { return ARPIPE_REAL(PollFn, poll)(fds, nfds, timeout); }

// The kernel's POLLIN_SET, POLLOUT_SET and POLLEX_SET (fs/select.c).
constexpr short kInSet = POLLRDNORM | POLLRDBAND | POLLIN | POLLHUP | POLLERR;
constexpr short kOutSet = POLLWRBAND | POLLWRNORM | POLLOUT | POLLERR;
constexpr short kExSet = POLLPRI;

bool any_tracked(int nfds, const fd_set* r, const fd_set* w, const fd_set* e) {
  if (nfds > FD_SETSIZE) nfds = FD_SETSIZE;
  for (int fd = 0; fd < nfds; ++fd)
    if (is_tracked(fd) && ((r && FD_ISSET(fd, r)) || (w && FD_ISSET(fd, w)) || (e && FD_ISSET(fd, e)))) return true;
  return false;
}

// Timeouts in whole milliseconds, rounded up (never shorter than asked); -1: no timeout.
int timeout_ms(const timespec* t) {
  if (t == nullptr) return -1;
  const int64_t ms = int64_t(t->tv_sec) * 1000 + (t->tv_nsec + 999999) / 1000000;
  return ms > INT_MAX ? INT_MAX : int(ms < 0 ? 0 : ms);
}

// select() through the registry's poll(); returns the ready count, as select counts (each set bit).
int select_by_poll(int nfds, fd_set* r, fd_set* w, fd_set* e, int timeout) {
  if (nfds < 0 || nfds > FD_SETSIZE) {
    errno = EINVAL;
    return -1;
  }
  std::vector<pollfd> fds;
  for (int fd = 0; fd < nfds; ++fd) {
    short events = 0;
    if (r && FD_ISSET(fd, r)) events |= POLLIN | POLLRDNORM;
    if (w && FD_ISSET(fd, w)) events |= POLLOUT | POLLWRNORM;
    if (e && FD_ISSET(fd, e)) events |= POLLPRI;
    if (events != 0) fds.push_back({fd, events, 0});
  }
  const int n = Registry::get().poll(fds.data(), fds.size(), timeout, real_poll);
  if (n < 0) return -1;
  int ready = 0;
  for (const pollfd& p : fds) {
    if (p.revents & POLLNVAL) {
      errno = EBADF;
      return -1;
    }
    const bool in = r && FD_ISSET(p.fd, r) && (p.revents & kInSet);
    const bool out = w && FD_ISSET(p.fd, w) && (p.revents & kOutSet);
    const bool ex = e && FD_ISSET(p.fd, e) && (p.revents & kExSet);
    if (r && !in) FD_CLR(p.fd, r);
    if (w && !out) FD_CLR(p.fd, w);
    if (e && !ex) FD_CLR(p.fd, e);
    ready += int(in) + int(out) + int(ex);
  }
  return ready;
}

// Runs f with the signal mask `mask` in place (pselect's and ppoll's atomic mask swap, not atomic here).
template <typename F>
int with_mask(const sigset_t* mask, F f) {
  sigset_t old;
  if (mask != nullptr) pthread_sigmask(SIG_SETMASK, mask, &old);
  const int r = f();
  const int saved = errno;
  if (mask != nullptr) pthread_sigmask(SIG_SETMASK, &old, nullptr);
  errno = saved;
  return r;
}

int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

#define ARPIPE_EXPORT extern "C" __attribute__((visibility("default")))

ARPIPE_EXPORT int select(int nfds, fd_set* r, fd_set* w, fd_set* e, timeval* timeout) {
  if (!any_tracked(nfds, r, w, e)) return ARPIPE_REAL(SelectFn, select)(nfds, r, w, e, timeout);
  timespec t{};
  if (timeout != nullptr) t = {timeout->tv_sec, long(timeout->tv_usec) * 1000};
  const int64_t start = now_ns();
  const int n = select_by_poll(nfds, r, w, e, timeout_ms(timeout ? &t : nullptr));
  if (timeout != nullptr) {  // Linux's select leaves the time not slept
    const int64_t left = std::max<int64_t>(0, int64_t(t.tv_sec) * 1000000000 + t.tv_nsec - (now_ns() - start));
    timeout->tv_sec = left / 1000000000;
    timeout->tv_usec = (left % 1000000000) / 1000;
  }
  return n;
}

ARPIPE_EXPORT int pselect(int nfds, fd_set* r, fd_set* w, fd_set* e, const timespec* timeout, const sigset_t* mask) {
  if (!any_tracked(nfds, r, w, e)) return ARPIPE_REAL(PselectFn, pselect)(nfds, r, w, e, timeout, mask);
  return with_mask(mask, [&] { return select_by_poll(nfds, r, w, e, timeout_ms(timeout)); });
}

ARPIPE_EXPORT int ppoll(pollfd* fds, nfds_t nfds, const timespec* timeout, const sigset_t* mask) {
  bool tracked = false;
  for (nfds_t i = 0; fds != nullptr && i < nfds; ++i) tracked = tracked || is_tracked(fds[i].fd);
  if (!tracked) return ARPIPE_REAL(PpollFn, ppoll)(fds, nfds, timeout, mask);
  return with_mask(mask, [&] { return Registry::get().poll(fds, nfds, timeout_ms(timeout), real_poll); });
}

ARPIPE_EXPORT int __ppoll_chk(pollfd* fds, nfds_t nfds, const timespec* timeout, const sigset_t* mask, size_t fdslen) {
  bool tracked = false;
  for (nfds_t i = 0; fds != nullptr && nfds <= fdslen / sizeof(pollfd) && i < nfds; ++i)
    tracked = tracked || is_tracked(fds[i].fd);
  if (!tracked) return ARPIPE_REAL(PpollChkFn, __ppoll_chk)(fds, nfds, timeout, mask, fdslen);
  return with_mask(mask, [&] { return Registry::get().poll(fds, nfds, timeout_ms(timeout), real_poll); });
}
