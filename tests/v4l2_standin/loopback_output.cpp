#include "loopback_output.h"

#include <linux/version.h>
#include <poll.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <numeric>

namespace arpipe::standin {

namespace {

constexpr uint32_t kLoopbackOutputType = V4L2_BUF_TYPE_VIDEO_OUTPUT;
constexpr uint32_t kLoopbackOutputMaxBuffers = 32;  // VIDEO_MAX_FRAME

PixelFormat loopback_raw_format(OfferedFormatName name) {
  switch (name) {
    case OfferedFormatName::Rgb24: return PixelFormat::RGB24;
    case OfferedFormatName::Grey: return PixelFormat::GREY;
    case OfferedFormatName::Nv12: return PixelFormat::NV12;
    default: break;  // YUYV; the config admits these raw formats only
  }
  return PixelFormat::YUYV;
}

// Size steps a format needs (4:2:2 pairs columns, 4:2:0 also rows).
uint32_t loopback_width_step(PixelFormat f) { return f == PixelFormat::YUYV || f == PixelFormat::NV12 ? 2 : 1; }
uint32_t loopback_height_step(PixelFormat f) { return f == PixelFormat::NV12 ? 2 : 1; }

const char* loopback_format_description(PixelFormat f) {
  switch (f) {
    case PixelFormat::YUYV: return "YUYV 4:2:2";
    case PixelFormat::RGB24: return "24-bit RGB 8-8-8";
    case PixelFormat::GREY: return "8-bit Greyscale";
    case PixelFormat::NV12: return "Y/CbCr 4:2:0";  // v4l2-compliance 1.22's words
    default: break;  // a loopback takes only the formats above (standin_config.cpp)
  }
  return "?";
}

}  // namespace

LoopbackOutput::LoopbackOutput(const LoopbackConfig& config)
    : LoopbackNode(kLoopbackOutputType, POLLOUT | POLLWRNORM, PROT_WRITE),
      config_(config),
      writer_(config_.spool, config_.max_spool_bytes),
      format_(spool_format(offered(0), std::min(640, config_.max_width) & ~1, std::min(480, config_.max_height) & ~1)),
      stall_fired_(config_.stalls.size(), false) {}

PixelFormat LoopbackOutput::offered(size_t index) const { return loopback_raw_format(config_.formats[index]); }

int64_t LoopbackOutput::next_wake(int64_t now) const {
  if (streaming_ && !buffers_.queued.empty() && hold_until_ > now) return hold_until_;
  return kNever;
}

void LoopbackOutput::advance(int64_t now) {
  while (streaming_ && !buffers_.queued.empty() && now >= hold_until_) {
    for (size_t i = 0; i < config_.stalls.size(); ++i)
      if (!stall_fired_[i] && config_.stalls[i].frame == taken_) {
        stall_fired_[i] = true;
        hold_until_ = std::max(hold_until_, now + config_.stalls[i].duration_ns);
      }
    if (now < hold_until_) break;
    const uint32_t index = buffers_.queued.front();
    buffers_.queued.pop_front();
    take(index, now);
  }
}

void LoopbackOutput::take(uint32_t index, int64_t now) {
  MmapBuffers::State& s = buffers_.state(index);
  SpoolFrame frame;
  frame.format = format_;
  frame.bytes_used = s.bytes_used;
  frame.sequence = sequence_;
  // v4l2loopback: the writer's timestamp when it gave one, else the time the frame was written.
  frame.timestamp_copied = s.timestamp_ns != 0;
  frame.timestamp_ns = frame.timestamp_copied ? s.timestamp_ns : now / 1000 * 1000;
  const std::string why = writer_.append(frame, buffers_.data(index));
  s.queued = false;
  s.done = true;
  s.error = !why.empty();
  s.sequence = sequence_++;
  s.timestamp_ns = frame.timestamp_ns;
  buffers_.done.push_back(index);
  ++taken_;
  if (why.empty()) {
    ++stats.frames_written;
    if (failing_) std::fprintf(stderr, "arpipe-v4l2-standin: %s: frames reach the spool again\n", config_.output.c_str());
    failing_ = false;
  } else {
    ++stats.error_buffers;
    if (!failing_) std::fprintf(stderr, "arpipe-v4l2-standin: %s: frame not spooled: %s\n", config_.output.c_str(), why.c_str());
    failing_ = true;
  }
}

void LoopbackOutput::save_format() {
  const std::string why = writer_.write_format(format_);
  if (!why.empty() && why != format_failure_)
    std::fprintf(stderr, "arpipe-v4l2-standin: %s: cannot write the spool's format: %s\n", config_.output.c_str(), why.c_str());
  format_failure_ = why;
}

// ---- ioctls ------------------------------------------------------------------------------------

int LoopbackOutput::ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) {
  if (arg == nullptr) return EFAULT;
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto& cap = *static_cast<v4l2_capability*>(arg);
      std::memset(&cap, 0, sizeof cap);
      copy_name(cap.driver, sizeof cap.driver, "arpipe-standin");
      copy_name(cap.card, sizeof cap.card, config_.card);
      copy_name(cap.bus_info, sizeof cap.bus_info, config_.bus_info);
      cap.version = LINUX_VERSION_CODE;
      cap.device_caps = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT;
      cap.capabilities = cap.device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto& d = *static_cast<v4l2_fmtdesc*>(arg);
      if (d.type != kLoopbackOutputType || d.index >= config_.formats.size()) return EINVAL;
      const uint32_t index = d.index;
      std::memset(&d, 0, sizeof d);
      d.index = index;
      d.type = kLoopbackOutputType;
      d.pixelformat = pixel_format_fourcc(offered(index));
      copy_name(d.description, sizeof d.description, loopback_format_description(offered(index)));
      return 0;
    }
    case VIDIOC_ENUM_FRAMESIZES: return enum_framesizes(*static_cast<v4l2_frmsizeenum*>(arg));
    case VIDIOC_G_FMT: {
      auto& f = *static_cast<v4l2_format*>(arg);
      if (f.type != kLoopbackOutputType) return EINVAL;
      fill_format(format_, f);
      return 0;
    }
    case VIDIOC_TRY_FMT:
    case VIDIOC_S_FMT: {
      auto& f = *static_cast<v4l2_format*>(arg);
      if (f.type != kLoopbackOutputType) return EINVAL;
      const SpoolFormat adjusted = adjust(f);
      if (request == VIDIOC_S_FMT) {
        if (busy(file) || !buffers_.empty()) return EBUSY;  // vb2: not while buffers are allocated
        format_ = adjusted;
        save_format();
      }
      fill_format(adjusted, f);
      return 0;
    }
    case VIDIOC_G_PARM: return parm(*static_cast<v4l2_streamparm*>(arg), false);
    case VIDIOC_S_PARM: return parm(*static_cast<v4l2_streamparm*>(arg), true);
    case VIDIOC_ENUMOUTPUT: {
      auto& out = *static_cast<v4l2_output*>(arg);
      if (out.index != 0) return EINVAL;
      std::memset(&out, 0, sizeof out);
      copy_name(out.name, sizeof out.name, "loopback in");
      out.type = V4L2_OUTPUT_TYPE_ANALOG;
      return 0;
    }
    case VIDIOC_G_OUTPUT: *static_cast<int*>(arg) = 0; return 0;
    case VIDIOC_S_OUTPUT: return *static_cast<int*>(arg) == 0 ? 0 : EINVAL;
    case VIDIOC_REQBUFS: return reqbufs(file, *static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF: {
      auto& b = *static_cast<v4l2_buffer*>(arg);
      if (b.type != kLoopbackOutputType || b.index >= buffers_.count()) return EINVAL;
      buffers_.fill(b.index, kLoopbackOutputType, b);
      return 0;
    }
    case VIDIOC_QBUF: return qbuf(file, *static_cast<v4l2_buffer*>(arg));
    case VIDIOC_DQBUF: return dqbuf(file, *static_cast<v4l2_buffer*>(arg), wait);
    case VIDIOC_STREAMON:
      if (*static_cast<int*>(arg) != int(kLoopbackOutputType)) return EINVAL;
      return streamon(file);
    case VIDIOC_STREAMOFF:
      if (*static_cast<int*>(arg) != int(kLoopbackOutputType)) return EINVAL;
      if (busy(file)) return EBUSY;
      stop_streaming();  // frames still queued are not written
      return 0;
    default: return ENOTTY;
  }
}

SpoolFormat LoopbackOutput::adjust(const v4l2_format& f) const {
  PixelFormat format = offered(0);  // an unknown format becomes the first offered, as drivers do
  for (size_t i = 0; i < config_.formats.size(); ++i)
    if (pixel_format_fourcc(offered(i)) == f.fmt.pix.pixelformat) format = offered(i);
  const uint32_t ws = loopback_width_step(format), hs = loopback_height_step(format);
  const uint32_t w = std::clamp<uint32_t>(f.fmt.pix.width, ws, uint32_t(config_.max_width)) / ws * ws;
  const uint32_t h = std::clamp<uint32_t>(f.fmt.pix.height, hs, uint32_t(config_.max_height)) / hs * hs;
  SpoolFormat s = spool_format(format, w, h);
  s.interval_num = format_.interval_num;
  s.interval_den = format_.interval_den;
  return s;
}

void LoopbackOutput::fill_format(const SpoolFormat& s, v4l2_format& f) const {
  std::memset(&f.fmt, 0, sizeof f.fmt);
  f.type = kLoopbackOutputType;
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

int LoopbackOutput::enum_framesizes(v4l2_frmsizeenum& e) const {
  std::optional<PixelFormat> format;
  for (size_t i = 0; i < config_.formats.size(); ++i)
    if (pixel_format_fourcc(offered(i)) == e.pixel_format) format = offered(i);
  if (!format || e.index != 0) return EINVAL;
  const uint32_t pixel_format = e.pixel_format;
  std::memset(&e, 0, sizeof e);
  e.pixel_format = pixel_format;
  e.type = V4L2_FRMSIZE_TYPE_STEPWISE;
  e.stepwise.min_width = e.stepwise.step_width = loopback_width_step(*format);
  e.stepwise.min_height = e.stepwise.step_height = loopback_height_step(*format);
  e.stepwise.max_width = uint32_t(config_.max_width) / e.stepwise.step_width * e.stepwise.step_width;
  e.stepwise.max_height = uint32_t(config_.max_height) / e.stepwise.step_height * e.stepwise.step_height;
  return 0;
}

int LoopbackOutput::parm(v4l2_streamparm& p, bool set) {
  if (p.type != kLoopbackOutputType) return EINVAL;
  if (set) {
    const v4l2_fract t = p.parm.output.timeperframe;
    if (t.numerator > 0 && t.denominator > 0) {  // zero keeps the current interval
      const uint32_t g = std::gcd(t.numerator, t.denominator);
      format_.interval_num = t.numerator / g;
      format_.interval_den = t.denominator / g;
      save_format();
    }
  }
  std::memset(&p.parm, 0, sizeof p.parm);
  p.parm.output.capability = V4L2_CAP_TIMEPERFRAME;
  p.parm.output.timeperframe = {format_.interval_num, format_.interval_den};
  return 0;
}

int LoopbackOutput::reqbufs(OpenFile& file, v4l2_requestbuffers& r) {
  r.capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP | V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS;
  if (r.type != kLoopbackOutputType || r.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file) || streaming_) return EBUSY;
  r.flags = 0;
  std::memset(r.reserved, 0, sizeof r.reserved);
  buffers_.release();
  owner_ = nullptr;
  if (r.count == 0) return 0;
  const uint32_t count = std::clamp<uint32_t>(r.count, 1, kLoopbackOutputMaxBuffers);
  if (const int err = buffers_.allocate(count, format_.size_image)) return err;
  for (uint32_t i = 0; i < count; ++i) buffers_.state(i).timestamp_flags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
  owner_ = &file;
  r.count = count;
  return 0;
}

int LoopbackOutput::qbuf(OpenFile& file, v4l2_buffer& b) {
  if (b.type != kLoopbackOutputType || b.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file)) return EBUSY;
  if (b.index >= buffers_.count()) return EINVAL;
  MmapBuffers::State& s = buffers_.state(b.index);
  if (s.queued || s.done) return EINVAL;  // vb2: the buffer is not in dequeued state
  // vb2: bytesused 0 on an output buffer means the whole buffer (deprecated, still accepted).
  const uint32_t used = b.bytesused == 0 ? buffers_.length() : b.bytesused;
  if (used > buffers_.length()) return EINVAL;
  // A timeval far outside int64 nanoseconds, or with microseconds out of range, is refused.
  if (b.timestamp.tv_usec < 0 || b.timestamp.tv_usec >= 1000000 || b.timestamp.tv_sec > INT64_MAX / 1000000000 - 1 ||
      b.timestamp.tv_sec < INT64_MIN / 1000000000 + 1)
    return EINVAL;
  s.bytes_used = used;
  s.timestamp_ns = int64_t(b.timestamp.tv_sec) * 1000000000 + int64_t(b.timestamp.tv_usec) * 1000;
  s.queued = true;
  s.error = false;
  buffers_.queued.push_back(b.index);
  buffers_.fill(b.index, kLoopbackOutputType, b);
  advance(monotonic_ns());
  return 0;
}

int LoopbackOutput::streamon(OpenFile& file) {
  if (busy(file)) return EBUSY;
  if (buffers_.empty()) return EINVAL;
  if (streaming_) return 0;
  streaming_ = true;
  ++stats.streamons;
  sequence_ = 0;
  writer_.rescan();  // another writer may have added frames since this one last wrote
  save_format();
  advance(monotonic_ns());
  return 0;
}

}  // namespace arpipe::standin
