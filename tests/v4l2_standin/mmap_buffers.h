// The buffers of a loopback node's queue: one memfd holding `count` page-aligned buffers that the
// host maps at their offsets (so two mappings see the same bytes), with each buffer's V4L2 state.
#pragma once

#include <linux/videodev2.h>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace arpipe::standin {

class MmapBuffers {
 public:
  struct State {
    bool queued = false, done = false, mapped = false, error = false;
    uint32_t bytes_used = 0, sequence = 0;
    int64_t timestamp_ns = 0;
    uint32_t timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  };

  MmapBuffers() = default;
  ~MmapBuffers() { release(); }
  MmapBuffers(const MmapBuffers&) = delete;
  MmapBuffers& operator=(const MmapBuffers&) = delete;

  // `count` buffers of `length` bytes: 0 or an errno (ENOMEM).
  int allocate(uint32_t count, uint32_t length);
  // Frees them (the host's mappings keep the memory: orphaned buffers) and forgets the queues.
  void release();
  bool empty() const { return states_.empty(); }
  uint32_t count() const { return uint32_t(states_.size()); }
  uint32_t length() const { return length_; }
  uint8_t* data(uint32_t index) { return memory_ + size_t(index) * stride_; }
  State& state(uint32_t index) { return states_[index]; }
  // Every buffer back to userspace, done ones cleared (STREAMOFF).
  void return_all();
  // The host's mmap: MAP_SHARED, PROT_READ or PROT_WRITE as `needed`; MAP_FAILED with errno.
  void* map(void* addr, size_t length, int prot, int flags, int64_t offset, int needed);
  // A v4l2_buffer as QUERYBUF/QBUF/DQBUF answer it.
  void fill(uint32_t index, uint32_t type, v4l2_buffer& b) const;

  std::deque<uint32_t> queued, done;

 private:
  int memfd_ = -1;
  uint8_t* memory_ = nullptr;
  size_t stride_ = 0;
  uint32_t length_ = 0;
  std::vector<State> states_;
};

}  // namespace arpipe::standin
