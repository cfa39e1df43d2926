#include "capture/v4l2/v4l2_mmap_buffers.h"

#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "capture/live/camera_stream.h"
#include "capture/v4l2/v4l2_device.h"

namespace arpipe {

namespace {

CameraError buffer_error(const V4L2Device& device, const char* what, int err) {
  return CameraError(err == ENODEV ? CameraError::Kind::Missing : CameraError::Kind::Failed,
                     fmt::format("{}: {}: {}", device.path(), what, std::strerror(err)));
}

}  // namespace

V4L2MmapBuffers::V4L2MmapBuffers(const V4L2Device& device, uint32_t count) : device_(device) {
  v4l2_requestbuffers request{};
  request.count = count;
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (const int err = device.ioctl(VIDIOC_REQBUFS, &request); err != 0) throw buffer_error(device, "VIDIOC_REQBUFS", err);
  if (request.count < count) {
    v4l2_requestbuffers none{};
    none.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    none.memory = V4L2_MEMORY_MMAP;
    device.ioctl(VIDIOC_REQBUFS, &none);
    throw CameraError(CameraError::Kind::Refused,
                      fmt::format("{}: asked for {} buffers, the driver gives {}", device.path(), count, request.count));
  }
  buffers_.resize(request.count);
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer buffer{};
    buffer.index = i;
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (const int err = device.ioctl(VIDIOC_QUERYBUF, &buffer); err != 0) {
      buffers_.resize(i);
      release();
      throw buffer_error(device, "VIDIOC_QUERYBUF", err);
    }
    void* start = mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, device.fd(), buffer.m.offset);
    if (start == MAP_FAILED) {
      const int err = errno;
      buffers_.resize(i);
      release();
      throw buffer_error(device, "mmap of a capture buffer", err);
    }
    buffers_[i] = {start, buffer.length};
  }
}

V4L2MmapBuffers::~V4L2MmapBuffers() { release(); }

void V4L2MmapBuffers::release() noexcept {
  for (const auto& mapping : buffers_)
    if (mapping.start) munmap(mapping.start, mapping.length);
  buffers_.clear();
  v4l2_requestbuffers none{};
  none.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  none.memory = V4L2_MEMORY_MMAP;
  device_.ioctl(VIDIOC_REQBUFS, &none);  // fails harmlessly (ENODEV) once the camera is gone
}

int V4L2MmapBuffers::queue(uint32_t index) const noexcept {
  v4l2_buffer buffer{};
  buffer.index = index;
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  return device_.ioctl(VIDIOC_QBUF, &buffer);
}

}  // namespace arpipe
