// A V4L2 device's MMAP capture buffers: requested, queried, mapped (each plane of a multi-planar
// buffer on its own), and freed on destruction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace arpipe {

class V4L2Device;

class V4L2MmapBuffers {
 public:
  // Requests `count` buffers of the device's buffer type with `planes` memory planes each (1 for
  // single-planar; the driver may give more buffers; fewer than `count` is refused with a
  // CameraError naming the device) and maps them.
  V4L2MmapBuffers(const V4L2Device& device, uint32_t count, uint32_t planes = 1);
  ~V4L2MmapBuffers();  // unmaps and frees them (REQBUFS 0); the stream must be off
  V4L2MmapBuffers(const V4L2MmapBuffers&) = delete;
  V4L2MmapBuffers& operator=(const V4L2MmapBuffers&) = delete;

  uint32_t count() const { return uint32_t(buffers_.size()); }
  uint32_t planes() const { return planes_; }
  const uint8_t* data(uint32_t index, uint32_t plane = 0) const {
    return static_cast<const uint8_t*>(buffers_[index][plane].start);
  }
  size_t length(uint32_t index, uint32_t plane = 0) const { return buffers_[index][plane].length; }
  // Queues buffer `index` (0 or the errno).
  int queue(uint32_t index) const noexcept;

 private:
  struct Mapping {
    void* start = nullptr;
    size_t length = 0;
  };
  void release() noexcept;
  const V4L2Device& device_;
  uint32_t type_ = 0;
  uint32_t planes_ = 1;
  std::vector<std::vector<Mapping>> buffers_;  // [buffer][plane]
};

}  // namespace arpipe
