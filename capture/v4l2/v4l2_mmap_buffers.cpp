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

V4L2MmapBuffers::V4L2MmapBuffers(const V4L2Device& device, uint32_t count, uint32_t planes)
    : device_(device), type_(device.buffer_type()), planes_(planes) {
  const bool mplane = device.multi_planar();
  if (planes_ < 1 || planes_ > VIDEO_MAX_PLANES || (!mplane && planes_ != 1))
    throw CameraError(CameraError::Kind::Failed,
                      fmt::format("{}: {} planes a buffer cannot be mapped", device.path(), planes_));
  v4l2_requestbuffers request{};
  request.count = count;
  request.type = type_;
  request.memory = V4L2_MEMORY_MMAP;
  if (const int err = device.ioctl(VIDIOC_REQBUFS, &request); err != 0) throw buffer_error(device, "VIDIOC_REQBUFS", err);
  if (request.count < count) {
    v4l2_requestbuffers none{};
    none.type = type_;
    none.memory = V4L2_MEMORY_MMAP;
    device.ioctl(VIDIOC_REQBUFS, &none);
    throw CameraError(CameraError::Kind::Refused,
                      fmt::format("{}: asked for {} buffers, the driver gives {}", device.path(), count, request.count));
  }
  buffers_.reserve(request.count);
  for (uint32_t i = 0; i < request.count; ++i) {
    v4l2_plane plane_info[VIDEO_MAX_PLANES] = {};
    v4l2_buffer buffer{};
    buffer.index = i;
    buffer.type = type_;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (mplane) {
      buffer.m.planes = plane_info;
      buffer.length = planes_;
    }
    if (const int err = device.ioctl(VIDIOC_QUERYBUF, &buffer); err != 0) {
      release();
      throw buffer_error(device, "VIDIOC_QUERYBUF", err);
    }
    if (mplane && buffer.length != planes_) {
      release();
      throw CameraError(CameraError::Kind::Failed, fmt::format("{}: buffer {} has {} planes, the format {}",
                                                               device.path(), i, buffer.length, planes_));
    }
    std::vector<Mapping>& mappings = buffers_.emplace_back();
    for (uint32_t p = 0; p < planes_; ++p) {
      const size_t length = mplane ? plane_info[p].length : buffer.length;
      const off_t offset = off_t(mplane ? plane_info[p].m.mem_offset : buffer.m.offset);
      void* start = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, device.fd(), offset);
      if (start == MAP_FAILED) {
        const int err = errno;
        release();
        throw buffer_error(device, "mmap of a capture buffer", err);
      }
      mappings.push_back({start, length});
    }
  }
}

V4L2MmapBuffers::~V4L2MmapBuffers() { release(); }

void V4L2MmapBuffers::release() noexcept {
  for (const auto& buffer : buffers_)
    for (const auto& mapping : buffer)
      if (mapping.start) munmap(mapping.start, mapping.length);
  buffers_.clear();
  v4l2_requestbuffers none{};
  none.type = type_;
  none.memory = V4L2_MEMORY_MMAP;
  device_.ioctl(VIDIOC_REQBUFS, &none);  // fails harmlessly (ENODEV) once the camera is gone
}

int V4L2MmapBuffers::queue(uint32_t index) const noexcept {
  v4l2_plane planes[VIDEO_MAX_PLANES] = {};
  v4l2_buffer buffer{};
  buffer.index = index;
  buffer.type = type_;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (type_ == V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE) {
    buffer.m.planes = planes;
    buffer.length = planes_;
  }
  return device_.ioctl(VIDIOC_QBUF, &buffer);
}

}  // namespace arpipe
