#include "loopback_capture.h"

#include <fmt/format.h>
#include <linux/version.h>
#include <poll.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace arpipe::standin {

namespace {

constexpr uint32_t kLoopbackCaptureType = V4L2_BUF_TYPE_VIDEO_CAPTURE;
constexpr uint32_t kLoopbackCaptureMaxBuffers = 32;  // VIDEO_MAX_FRAME
// How often a stream waiting for the writer looks at the spool (the writer may be another process).
constexpr int64_t kSpoolLookNs = 5000000;

std::string loopback_format_phrase(const SpoolFormat& f) {
  return fmt::format("{} {}x{} ({} bytes a line)", pixel_format_name(f.format), f.width, f.height, f.bytes_per_line);
}

}  // namespace

LoopbackCapture::LoopbackCapture(const LoopbackConfig& config)
    : LoopbackNode(kLoopbackCaptureType, POLLIN | POLLRDNORM, PROT_READ), config_(config), reader_(config_.spool) {}

void LoopbackCapture::queue_released() { negotiated_.reset(); }

std::optional<SpoolFormat> LoopbackCapture::current_format() {
  if (negotiated_) return negotiated_;
  std::string error;
  const auto format = reader_.read_format(error);
  if (!error.empty() && error != format_error_) std::fprintf(stderr, "arpipe-v4l2-standin: %s\n", error.c_str());
  format_error_ = error;
  return format;
}

int64_t LoopbackCapture::next_wake(int64_t now) const {
  return streaming_ && !buffers_.queued.empty() ? now + kSpoolLookNs : kNever;
}

void LoopbackCapture::advance(int64_t) {
  while (streaming_ && !buffers_.queued.empty()) {
    const uint32_t index = buffers_.queued.front();
    SpoolFrame frame;
    std::string error;
    SpoolReader::Result result = reader_.read_frame(next_frame_, frame, buffers_.data(index), buffers_.length(), error);
    if (result == SpoolReader::Result::Absent) return;  // not written yet
    if (result == SpoolReader::Result::Ok && !(frame.format.format == negotiated_->format &&
                                               frame.format.width == negotiated_->width &&
                                               frame.format.height == negotiated_->height &&
                                               frame.format.bytes_per_line == negotiated_->bytes_per_line)) {
      // The writer changed its format under a running stream: this reader cannot take the frame.
      error = fmt::format("{}: the frame is {}, the stream is {}", reader_.frame_path(next_frame_).string(),
                          loopback_format_phrase(frame.format), loopback_format_phrase(*negotiated_));
      result = SpoolReader::Result::Bad;
    }
    buffers_.queued.pop_front();
    MmapBuffers::State& s = buffers_.state(index);
    s.queued = false;
    s.done = true;
    s.error = result != SpoolReader::Result::Ok;
    s.bytes_used = s.error ? 0 : frame.bytes_used;
    s.sequence = sequence_++;
    s.timestamp_ns = frame.timestamp_ns;
    s.timestamp_flags = frame.timestamp_copied ? V4L2_BUF_FLAG_TIMESTAMP_COPY : V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    buffers_.done.push_back(index);
    ++next_frame_;
    ++stats.frames_delivered;
    if (s.error) {
      ++stats.error_buffers;
      std::fprintf(stderr, "arpipe-v4l2-standin: %s (served as an error buffer)\n", error.c_str());
    }
  }
}

// ---- ioctls ------------------------------------------------------------------------------------

int LoopbackCapture::ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) {
  if (arg == nullptr) return EFAULT;
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto& cap = *static_cast<v4l2_capability*>(arg);
      std::memset(&cap, 0, sizeof cap);
      copy_name(cap.driver, sizeof cap.driver, "arpipe-standin");
      copy_name(cap.card, sizeof cap.card, config_.card);
      copy_name(cap.bus_info, sizeof cap.bus_info, config_.bus_info);
      cap.version = LINUX_VERSION_CODE;
      cap.device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT;
      cap.capabilities = cap.device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto& d = *static_cast<v4l2_fmtdesc*>(arg);
      const auto format = current_format();
      if (d.type != kLoopbackCaptureType || d.index != 0 || !format) return EINVAL;
      std::memset(&d, 0, sizeof d);
      d.type = kLoopbackCaptureType;
      d.pixelformat = pixel_format_fourcc(format->format);
      copy_name(d.description, sizeof d.description, std::string(pixel_format_name(format->format)));
      return 0;
    }
    case VIDIOC_ENUM_FRAMESIZES: {
      auto& e = *static_cast<v4l2_frmsizeenum*>(arg);
      const auto format = current_format();
      if (!format || e.index != 0 || e.pixel_format != pixel_format_fourcc(format->format)) return EINVAL;
      const uint32_t pixel_format = e.pixel_format;
      std::memset(&e, 0, sizeof e);
      e.pixel_format = pixel_format;
      e.type = V4L2_FRMSIZE_TYPE_DISCRETE;
      e.discrete = {format->width, format->height};
      return 0;
    }
    case VIDIOC_ENUM_FRAMEINTERVALS: {
      auto& e = *static_cast<v4l2_frmivalenum*>(arg);
      const auto format = current_format();
      if (!format || e.index != 0 || e.pixel_format != pixel_format_fourcc(format->format) || e.width != format->width ||
          e.height != format->height)
        return EINVAL;
      const v4l2_frmivalenum in = e;
      std::memset(&e, 0, sizeof e);
      e.pixel_format = in.pixel_format;
      e.width = in.width;
      e.height = in.height;
      e.type = V4L2_FRMIVAL_TYPE_DISCRETE;
      e.discrete = {format->interval_num, format->interval_den};
      return 0;
    }
    case VIDIOC_G_FMT:
    case VIDIOC_TRY_FMT:
    case VIDIOC_S_FMT: {
      // v4l2loopback: the writer's format is the only one; any request gets it.
      auto& f = *static_cast<v4l2_format*>(arg);
      if (f.type != kLoopbackCaptureType) return EINVAL;
      if (request == VIDIOC_S_FMT && busy(file)) return EBUSY;
      const auto format = current_format();
      if (!format) return EINVAL;  // no writer yet (v4l2loopback with exclusive_caps=1 is no capture device then)
      fill_format(*format, f);
      return 0;
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto& p = *static_cast<v4l2_streamparm*>(arg);
      if (p.type != kLoopbackCaptureType) return EINVAL;
      const auto format = current_format();
      std::memset(&p.parm, 0, sizeof p.parm);
      p.parm.capture.capability = V4L2_CAP_TIMEPERFRAME;  // the writer's interval; a request cannot change it
      p.parm.capture.timeperframe = format ? v4l2_fract{format->interval_num, format->interval_den} : v4l2_fract{1, 30};
      return 0;
    }
    case VIDIOC_ENUMINPUT: {
      auto& in = *static_cast<v4l2_input*>(arg);
      if (in.index != 0) return EINVAL;
      std::memset(&in, 0, sizeof in);
      copy_name(in.name, sizeof in.name, "loopback");
      in.type = V4L2_INPUT_TYPE_CAMERA;
      return 0;
    }
    case VIDIOC_G_INPUT: *static_cast<int*>(arg) = 0; return 0;
    case VIDIOC_S_INPUT: return *static_cast<int*>(arg) == 0 ? 0 : EINVAL;
    case VIDIOC_REQBUFS: return reqbufs(file, *static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF: {
      auto& b = *static_cast<v4l2_buffer*>(arg);
      if (b.type != kLoopbackCaptureType || b.index >= buffers_.count()) return EINVAL;
      buffers_.fill(b.index, kLoopbackCaptureType, b);
      return 0;
    }
    case VIDIOC_QBUF: return qbuf(file, *static_cast<v4l2_buffer*>(arg));
    case VIDIOC_DQBUF: return dqbuf(file, *static_cast<v4l2_buffer*>(arg), wait);
    case VIDIOC_STREAMON: {
      if (*static_cast<int*>(arg) != int(kLoopbackCaptureType)) return EINVAL;
      if (busy(file)) return EBUSY;
      if (buffers_.empty()) return EINVAL;
      if (streaming_) return 0;
      streaming_ = true;
      ++stats.streamons;
      sequence_ = 0;
      next_frame_ = reader_.first_index();  // every stream starts at the oldest frame in the spool
      advance(monotonic_ns());
      return 0;
    }
    case VIDIOC_STREAMOFF:
      if (*static_cast<int*>(arg) != int(kLoopbackCaptureType)) return EINVAL;
      if (busy(file)) return EBUSY;
      stop_streaming();
      return 0;
    default: return ENOTTY;
  }
}

void LoopbackCapture::fill_format(const SpoolFormat& s, v4l2_format& f) const {
  std::memset(&f.fmt, 0, sizeof f.fmt);
  f.type = kLoopbackCaptureType;
  v4l2_pix_format& p = f.fmt.pix;
  p.width = s.width;
  p.height = s.height;
  p.pixelformat = pixel_format_fourcc(s.format);
  p.field = V4L2_FIELD_NONE;
  p.bytesperline = s.bytes_per_line;
  p.sizeimage = s.size_image;
  p.colorspace = V4L2_COLORSPACE_SRGB;
  p.priv = V4L2_PIX_FMT_PRIV_MAGIC;
  p.ycbcr_enc = V4L2_YCBCR_ENC_601;
  const bool yuv = s.format == PixelFormat::YUYV || s.format == PixelFormat::NV12;
  p.quantization = yuv ? V4L2_QUANTIZATION_LIM_RANGE : V4L2_QUANTIZATION_FULL_RANGE;
  p.xfer_func = V4L2_XFER_FUNC_SRGB;
}

int LoopbackCapture::reqbufs(OpenFile& file, v4l2_requestbuffers& r) {
  r.capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP | V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS;
  if (r.type != kLoopbackCaptureType || r.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file) || streaming_) return EBUSY;
  r.flags = 0;
  std::memset(r.reserved, 0, sizeof r.reserved);
  buffers_.release();
  negotiated_.reset();
  owner_ = nullptr;
  if (r.count == 0) return 0;
  const auto format = current_format();
  if (!format) return EINVAL;  // no writer has set a format: nothing to size the buffers by
  const uint32_t count = std::clamp<uint32_t>(r.count, 1, kLoopbackCaptureMaxBuffers);
  if (const int err = buffers_.allocate(count, format->size_image)) return err;
  negotiated_ = format;
  owner_ = &file;
  r.count = count;
  return 0;
}

int LoopbackCapture::qbuf(OpenFile& file, v4l2_buffer& b) {
  if (b.type != kLoopbackCaptureType || b.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file)) return EBUSY;
  if (b.index >= buffers_.count()) return EINVAL;
  MmapBuffers::State& s = buffers_.state(b.index);
  if (s.queued || s.done) return EINVAL;
  s.queued = true;
  s.error = false;
  s.bytes_used = 0;
  buffers_.queued.push_back(b.index);
  buffers_.fill(b.index, kLoopbackCaptureType, b);
  advance(monotonic_ns());
  return 0;
}

}  // namespace arpipe::standin
