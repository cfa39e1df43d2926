// A V4L2 device's MMAP capture buffers: requested, queried, mapped, and freed on destruction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace arpipe {

class V4L2Device;

class V4L2MmapBuffers {
 public:
  // Requests `count` buffers (the driver may give more; fewer than `count` is refused with a
  // CameraError naming the device) and maps them.
  V4L2MmapBuffers(const V4L2Device& device, uint32_t count);
  ~V4L2MmapBuffers();  // unmaps and frees them (REQBUFS 0); the stream must be off
  V4L2MmapBuffers(const V4L2MmapBuffers&) = delete;
  V4L2MmapBuffers& operator=(const V4L2MmapBuffers&) = delete;

  uint32_t count() const { return uint32_t(buffers_.size()); }
  const uint8_t* data(uint32_t index) const { return static_cast<const uint8_t*>(buffers_[index].start); }
  size_t length(uint32_t index) const { return buffers_[index].length; }
  // Queues buffer `index` (0 or the errno).
  int queue(uint32_t index) const noexcept;

 private:
  struct Mapping {
    void* start = nullptr;
    size_t length = 0;
  };
  void release() noexcept;
  const V4L2Device& device_;
  std::vector<Mapping> buffers_;
};

}  // namespace arpipe
