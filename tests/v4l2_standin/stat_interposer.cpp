// The stat family on served paths and tracked fds: a character device of the video4linux major
// (81), as v4l2-ctl and v4l2-compliance insist (they stat() the path and fstat() the fd). The
// glibc < 2.33 entry points (__xstat & co., which older binaries call) answer the same.
#undef _FORTIFY_SOURCE

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

#include "next_symbol.h"
#include "standin_registry.h"

using arpipe::standin::identity_of_fd;
using arpipe::standin::identity_of_path;
using arpipe::standin::NodeIdentity;
using arpipe::standin::served_at;
using arpipe::standin::served_exactly_at;

namespace {

using StatFn = int (*)(const char*, struct stat*);
using FstatFn = int (*)(int, struct stat*);
using FstatatFn = int (*)(int, const char*, struct stat*, int);
using Stat64Fn = int (*)(const char*, struct stat64*);
using Fstat64Fn = int (*)(int, struct stat64*);
using Fstatat64Fn = int (*)(int, const char*, struct stat64*, int);
using StatxFn = int (*)(int, const char*, int, unsigned, struct statx*);

constexpr gid_t kVideoGroup = 44;  // Debian's "video" group, which owns /dev/video*
constexpr dev_t kDevtmpfs = 5;     // makedev(0, 5): devtmpfs, where /dev lives

// The node's identity for a path (symlinks followed unless `follow` is false), or false.
bool path_identity(int dirfd, const char* path, bool follow, NodeIdentity& out) {
  const std::string s = follow ? served_at(dirfd, path) : served_exactly_at(dirfd, path);
  return !s.empty() && identity_of_path(s, out);
}

// struct stat and struct stat64 have the same fields on 64-bit Linux.
template <typename Stat>
int fill(const NodeIdentity& id, Stat* st) {
  if (st == nullptr) {
    errno = EFAULT;
    return -1;
  }
  std::memset(st, 0, sizeof *st);
  st->st_dev = kDevtmpfs;
  st->st_ino = 1000 + id.minor;  // distinct per node, as devtmpfs numbers its inodes
  st->st_mode = S_IFCHR | 0660;
  st->st_nlink = 1;
  st->st_uid = 0;
  st->st_gid = kVideoGroup;
  st->st_rdev = makedev(arpipe::standin::kVideoMajor, id.minor);
  st->st_size = 0;
  st->st_blksize = 4096;
  st->st_blocks = 0;
  const timespec t{time_t(id.loaded_at_ns / 1000000000), long(id.loaded_at_ns % 1000000000)};
  st->st_atim = st->st_mtim = st->st_ctim = t;
  return 0;
}

int fill_statx(const NodeIdentity& id, unsigned mask, struct statx* sx) {
  if (sx == nullptr) {
    errno = EFAULT;
    return -1;
  }
  (void)mask;  // everything basic is known, so all of it is returned (as the kernel may)
  std::memset(sx, 0, sizeof *sx);
  sx->stx_mask = STATX_BASIC_STATS;
  sx->stx_blksize = 4096;
  sx->stx_nlink = 1;
  sx->stx_uid = 0;
  sx->stx_gid = kVideoGroup;
  sx->stx_mode = S_IFCHR | 0660;
  sx->stx_ino = 1000 + id.minor;
  sx->stx_rdev_major = arpipe::standin::kVideoMajor;
  sx->stx_rdev_minor = id.minor;
  sx->stx_dev_major = 0;
  sx->stx_dev_minor = kDevtmpfs;
  const statx_timestamp t{id.loaded_at_ns / 1000000000, uint32_t(id.loaded_at_ns % 1000000000), 0};
  sx->stx_atime = sx->stx_mtime = sx->stx_ctime = t;
  return 0;
}

bool empty_path(const char* path, int flags) { return (flags & AT_EMPTY_PATH) != 0 && path != nullptr && *path == '\0'; }

}  // namespace

#define ARPIPE_EXPORT extern "C" __attribute__((visibility("default")))

ARPIPE_EXPORT int stat(const char* path, struct stat* st) {
  NodeIdentity id;
  if (path_identity(AT_FDCWD, path, true, id)) return fill(id, st);
  return ARPIPE_REAL(StatFn, stat)(path, st);
}
ARPIPE_EXPORT int lstat(const char* path, struct stat* st) {
  NodeIdentity id;
  if (path_identity(AT_FDCWD, path, false, id)) return fill(id, st);
  return ARPIPE_REAL(StatFn, lstat)(path, st);
}
ARPIPE_EXPORT int fstat(int fd, struct stat* st) {
  NodeIdentity id;
  if (identity_of_fd(fd, id)) return fill(id, st);
  return ARPIPE_REAL(FstatFn, fstat)(fd, st);
}
ARPIPE_EXPORT int fstatat(int dirfd, const char* path, struct stat* st, int flags) {
  NodeIdentity id;
  if (empty_path(path, flags) ? identity_of_fd(dirfd, id)
                              : path_identity(dirfd, path, (flags & AT_SYMLINK_NOFOLLOW) == 0, id))
    return fill(id, st);
  return ARPIPE_REAL(FstatatFn, fstatat)(dirfd, path, st, flags);
}

ARPIPE_EXPORT int stat64(const char* path, struct stat64* st) {
  NodeIdentity id;
  if (path_identity(AT_FDCWD, path, true, id)) return fill(id, st);
  return ARPIPE_REAL(Stat64Fn, stat64)(path, st);
}
ARPIPE_EXPORT int lstat64(const char* path, struct stat64* st) {
  NodeIdentity id;
  if (path_identity(AT_FDCWD, path, false, id)) return fill(id, st);
  return ARPIPE_REAL(Stat64Fn, lstat64)(path, st);
}
ARPIPE_EXPORT int fstat64(int fd, struct stat64* st) {
  NodeIdentity id;
  if (identity_of_fd(fd, id)) return fill(id, st);
  return ARPIPE_REAL(Fstat64Fn, fstat64)(fd, st);
}
ARPIPE_EXPORT int fstatat64(int dirfd, const char* path, struct stat64* st, int flags) {
  NodeIdentity id;
  if (empty_path(path, flags) ? identity_of_fd(dirfd, id)
                              : path_identity(dirfd, path, (flags & AT_SYMLINK_NOFOLLOW) == 0, id))
    return fill(id, st);
  return ARPIPE_REAL(Fstatat64Fn, fstatat64)(dirfd, path, st, flags);
}

ARPIPE_EXPORT int statx(int dirfd, const char* path, int flags, unsigned mask, struct statx* sx) {
  NodeIdentity id;
  if (empty_path(path, flags) ? identity_of_fd(dirfd, id)
                              : path_identity(dirfd, path, (flags & AT_SYMLINK_NOFOLLOW) == 0, id))
    return fill_statx(id, mask, sx);
  return ARPIPE_REAL(StatxFn, statx)(dirfd, path, flags, mask, sx);
}

// glibc before 2.33 had stat() call these (binaries built then still do); on 64-bit Linux every
// `ver` they pass has the layout of struct stat, so they forward to the functions above, which
// glibc 2.33+ exports as real symbols.
ARPIPE_EXPORT int __xstat(int, const char* path, struct stat* st) { return stat(path, st); }
ARPIPE_EXPORT int __lxstat(int, const char* path, struct stat* st) { return lstat(path, st); }
ARPIPE_EXPORT int __fxstat(int, int fd, struct stat* st) { return fstat(fd, st); }
ARPIPE_EXPORT int __fxstatat(int, int dirfd, const char* path, struct stat* st, int flags) {
  return fstatat(dirfd, path, st, flags);
}
ARPIPE_EXPORT int __xstat64(int, const char* path, struct stat64* st) { return stat64(path, st); }
ARPIPE_EXPORT int __lxstat64(int, const char* path, struct stat64* st) { return lstat64(path, st); }
ARPIPE_EXPORT int __fxstat64(int, int fd, struct stat64* st) { return fstat64(fd, st); }
ARPIPE_EXPORT int __fxstatat64(int, int dirfd, const char* path, struct stat64* st, int flags) {
  return fstatat64(dirfd, path, st, flags);
}
