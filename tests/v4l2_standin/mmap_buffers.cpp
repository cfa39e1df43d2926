#include "mmap_buffers.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace arpipe::standin {

int MmapBuffers::allocate(uint32_t count, uint32_t length) {
  release();
  const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  length_ = length;
  stride_ = (size_t(length) + page - 1) / page * page;
  memfd_ = ::memfd_create("arpipe-v4l2-standin-loopback", MFD_CLOEXEC);
  if (memfd_ < 0) return ENOMEM;
  if (::ftruncate(memfd_, off_t(stride_ * count)) != 0) {
    release();
    return ENOMEM;
  }
  void* p = ::mmap(nullptr, stride_ * count, PROT_READ | PROT_WRITE, MAP_SHARED, memfd_, 0);
  if (p == MAP_FAILED) {
    release();
    return ENOMEM;
  }
  memory_ = static_cast<uint8_t*>(p);
  states_.assign(count, State{});
  return 0;
}

void MmapBuffers::release() {
  if (memory_ != nullptr) ::munmap(memory_, stride_ * states_.size());
  if (memfd_ >= 0) ::close(memfd_);
  memory_ = nullptr;
  memfd_ = -1;
  states_.clear();
  queued.clear();
  done.clear();
}

void MmapBuffers::return_all() {
  queued.clear();
  done.clear();
  for (State& s : states_) {
    s.queued = s.done = s.error = false;
    s.bytes_used = 0;
  }
}

void* MmapBuffers::map(void* addr, size_t length, int prot, int flags, int64_t offset, int needed) {
  const auto fail = [](int err) {
    errno = err;
    return MAP_FAILED;
  };
  if ((flags & MAP_SHARED) == 0 || (prot & needed) == 0) return fail(EINVAL);
  if (states_.empty() || offset < 0 || size_t(offset) % stride_ != 0) return fail(EINVAL);
  const size_t index = size_t(offset) / stride_;
  if (index >= states_.size() || length == 0 || length > stride_) return fail(EINVAL);
  void* p = ::mmap(addr, length, prot, flags, memfd_, off_t(offset));
  if (p == MAP_FAILED) return p;
  states_[index].mapped = true;
  return p;
}

void MmapBuffers::fill(uint32_t index, uint32_t type, v4l2_buffer& b) const {
  const State& s = states_[index];
  std::memset(&b, 0, sizeof b);
  b.index = index;
  b.type = type;
  b.memory = V4L2_MEMORY_MMAP;
  b.m.offset = uint32_t(size_t(index) * stride_);
  b.length = length_;
  b.field = V4L2_FIELD_NONE;
  b.flags = s.timestamp_flags;
  if (s.mapped) b.flags |= V4L2_BUF_FLAG_MAPPED;
  if (s.queued) b.flags |= V4L2_BUF_FLAG_QUEUED;
  if (s.done) b.flags |= V4L2_BUF_FLAG_DONE;
  if (s.error) b.flags |= V4L2_BUF_FLAG_ERROR;
  b.bytesused = s.bytes_used;
  b.sequence = s.sequence;
  // timeval as vb2 converts (whole microseconds, rounded down).
  const int64_t us = s.timestamp_ns >= 0 ? s.timestamp_ns / 1000 : -((-s.timestamp_ns + 999) / 1000);
  b.timestamp.tv_sec = us >= 0 ? us / 1000000 : -((-us + 999999) / 1000000);
  b.timestamp.tv_usec = us - int64_t(b.timestamp.tv_sec) * 1000000;
}

}  // namespace arpipe::standin
