// The libc functions the stand-in interposes (open*, close, dup*, fcntl, ioctl, mmap*, poll, read): calls on
// served paths and tracked fds go to the registry, everything else to the next definition (libc).
#undef _FORTIFY_SOURCE  // this file defines open() and friends; fortify would wrap them inline

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "next_symbol.h"
#include "standin_config.h"
#include "standin_registry.h"

using arpipe::standin::is_serving;
using arpipe::standin::is_tracked;
using arpipe::standin::served_at;
using arpipe::standin::Registry;

namespace {

using OpenFn = int (*)(const char*, int, ...);
using OpenatFn = int (*)(int, const char*, int, ...);
using Open2Fn = int (*)(const char*, int);
using Openat2Fn = int (*)(int, const char*, int);
using CloseFn = int (*)(int);
using DupFn = int (*)(int);
using Dup2Fn = int (*)(int, int);
using Dup3Fn = int (*)(int, int, int);
using FcntlFn = int (*)(int, int, ...);
using IoctlFn = int (*)(int, unsigned long, ...);
using MmapFn = void* (*)(void*, size_t, int, int, int, off_t);
using PollFn = int (*)(pollfd*, nfds_t, int);
using PollChkFn = int (*)(pollfd*, nfds_t, int, size_t);
using ReadFn = ssize_t (*)(int, void*, size_t);
using ReadChkFn = ssize_t (*)(int, void*, size_t, size_t);

bool wants_mode(int flags) { return (flags & O_CREAT) != 0 || (flags & O_TMPFILE) == O_TMPFILE; }

}  // namespace

#define ARPIPE_EXPORT extern "C" __attribute__((visibility("default")))

ARPIPE_EXPORT int open(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served_at(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenFn, open)(path, flags, mode);
}

ARPIPE_EXPORT int open64(const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served_at(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenFn, open64)(path, flags, mode);
}

ARPIPE_EXPORT int openat(int dirfd, const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served_at(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenatFn, openat)(dirfd, path, flags, mode);
}

ARPIPE_EXPORT int openat64(int dirfd, const char* path, int flags, ...) {
  mode_t mode = 0;
  if (wants_mode(flags)) {
    va_list ap;
    va_start(ap, flags);
    mode = va_arg(ap, mode_t);
    va_end(ap);
  }
  if (const std::string s = served_at(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(OpenatFn, openat64)(dirfd, path, flags, mode);
}

// The _FORTIFY_SOURCE entry points a host built with fortification calls instead.
ARPIPE_EXPORT int __open_2(const char* path, int flags) {
  if (const std::string s = served_at(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Open2Fn, __open_2)(path, flags);
}
ARPIPE_EXPORT int __open64_2(const char* path, int flags) {
  if (const std::string s = served_at(AT_FDCWD, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Open2Fn, __open64_2)(path, flags);
}
ARPIPE_EXPORT int __openat_2(int dirfd, const char* path, int flags) {
  if (const std::string s = served_at(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Openat2Fn, __openat_2)(dirfd, path, flags);
}
ARPIPE_EXPORT int __openat64_2(int dirfd, const char* path, int flags) {
  if (const std::string s = served_at(dirfd, path); !s.empty()) return Registry::get().open(s, flags);
  return ARPIPE_REAL(Openat2Fn, __openat64_2)(dirfd, path, flags);
}

// Duplicates of a tracked fd share its open file, as dup(2) shares the file description: the real
// dup of the eventfd is made first, then tracked.
ARPIPE_EXPORT int dup(int fd) noexcept {
  const int r = ARPIPE_REAL(DupFn, dup)(fd);
  if (r >= 0 && is_tracked(fd)) Registry::get().dup(fd, r);
  return r;
}

ARPIPE_EXPORT int dup2(int fd, int fd2) noexcept {
  if (is_tracked(fd2) && fd2 != fd) Registry::get().close(fd2);  // dup2 closes what fd2 was
  const int r = ARPIPE_REAL(Dup2Fn, dup2)(fd, fd2);
  if (r >= 0 && is_tracked(fd)) Registry::get().dup(fd, r);
  return r;
}

ARPIPE_EXPORT int dup3(int fd, int fd2, int flags) noexcept {
  if (is_tracked(fd2) && fd2 != fd) Registry::get().close(fd2);
  const int r = ARPIPE_REAL(Dup3Fn, dup3)(fd, fd2, flags);
  if (r >= 0 && is_tracked(fd)) Registry::get().dup(fd, r);
  return r;
}

namespace {
// fcntl's third argument is an int or a pointer; a long carries either (as glibc's own wrapper does).
int forward_fcntl(FcntlFn real, int fd, int cmd, long arg) {
  const int r = real(fd, cmd, arg);
  if (r >= 0 && (cmd == F_DUPFD || cmd == F_DUPFD_CLOEXEC) && is_tracked(fd)) Registry::get().dup(fd, r);
  return r;
}
}  // namespace

ARPIPE_EXPORT int fcntl(int fd, int cmd, ...) {
  va_list ap;
  va_start(ap, cmd);
  const long arg = va_arg(ap, long);
  va_end(ap);
  return forward_fcntl(ARPIPE_REAL(FcntlFn, fcntl), fd, cmd, arg);
}

ARPIPE_EXPORT int fcntl64(int fd, int cmd, ...) {
  va_list ap;
  va_start(ap, cmd);
  const long arg = va_arg(ap, long);
  va_end(ap);
  return forward_fcntl(ARPIPE_REAL(FcntlFn, fcntl64), fd, cmd, arg);
}

ARPIPE_EXPORT int close(int fd) {
  if (is_tracked(fd)) Registry::get().close(fd);
  return ARPIPE_REAL(CloseFn, close)(fd);
}

ARPIPE_EXPORT int ioctl(int fd, unsigned long request, ...) noexcept {
  va_list ap;
  va_start(ap, request);
  void* arg = va_arg(ap, void*);
  va_end(ap);
  if (is_tracked(fd)) {
    bool handled = false;
    const int r = Registry::get().ioctl(fd, request, arg, handled);
    if (handled) return r;
  }
  return ARPIPE_REAL(IoctlFn, ioctl)(fd, request, arg);
}

ARPIPE_EXPORT void* mmap(void* addr, size_t length, int prot, int flags, int fd, off_t offset) noexcept {
  if (is_tracked(fd)) {
    bool handled = false;
    void* p = Registry::get().mmap(fd, addr, length, prot, flags, offset, handled);
    if (handled) return p;
  }
  return ARPIPE_REAL(MmapFn, mmap)(addr, length, prot, flags, fd, offset);
}

ARPIPE_EXPORT void* mmap64(void* addr, size_t length, int prot, int flags, int fd, off64_t offset) noexcept {
  if (is_tracked(fd)) {
    bool handled = false;
    void* p = Registry::get().mmap(fd, addr, length, prot, flags, offset, handled);
    if (handled) return p;
  }
  return ARPIPE_REAL(MmapFn, mmap64)(addr, length, prot, flags, fd, offset);
}

namespace {
bool any_tracked(const pollfd* fds, nfds_t nfds) {
  for (nfds_t i = 0; i < nfds; ++i)
    if (is_tracked(fds[i].fd)) return true;
  return false;
}
int real_poll(pollfd* fds, nfds_t nfds, int timeout) { return ARPIPE_REAL(PollFn, poll)(fds, nfds, timeout); }
}  // namespace

// glibc declares poll's fds write-only (__attr_access ((__write_only__, 1, 2))), so GCC at -O1
// (CI's sanitizer build) warns that reading the caller's events "may be used uninitialized"; the
// caller fills them in, as poll(2) requires.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
ARPIPE_EXPORT int poll(pollfd* fds, nfds_t nfds, int timeout) {
  if (fds != nullptr && any_tracked(fds, nfds)) return Registry::get().poll(fds, nfds, timeout, real_poll);
  return real_poll(fds, nfds, timeout);
}
#pragma GCC diagnostic pop

ARPIPE_EXPORT int __poll_chk(pollfd* fds, nfds_t nfds, int timeout, size_t fdslen) {
  if (fds != nullptr && nfds <= fdslen / sizeof(pollfd) && any_tracked(fds, nfds))
    return Registry::get().poll(fds, nfds, timeout, real_poll);
  return ARPIPE_REAL(PollChkFn, __poll_chk)(fds, nfds, timeout, fdslen);
}

ARPIPE_EXPORT ssize_t read(int fd, void* buf, size_t count) {
  if (is_tracked(fd)) {  // no V4L2_CAP_READWRITE
    errno = EINVAL;
    return -1;
  }
  return ARPIPE_REAL(ReadFn, read)(fd, buf, count);
}

ARPIPE_EXPORT ssize_t __read_chk(int fd, void* buf, size_t count, size_t buflen) {
  if (is_tracked(fd)) {
    errno = EINVAL;
    return -1;
  }
  return ARPIPE_REAL(ReadChkFn, __read_chk)(fd, buf, count, buflen);
}
