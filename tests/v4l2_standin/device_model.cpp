#include "device_model.h"

#include <fcntl.h>
#include <linux/version.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <numeric>

namespace arpipe::standin {

namespace {

constexpr uint32_t kMaxBuffers = 32;  // VIDEO_MAX_FRAME; uvcvideo's UVC_MAX_VIDEO_BUFFERS

double max_digital_gain(const FrameSource& source) {
  double g = 0;
  for (size_t i = 0; i < source.frame_count(); ++i) g = std::max(g, source.metadata(i).digital_gain);
  return g;
}

void copy_name(uint8_t* dst, size_t size, const std::string& text) {
  std::memset(dst, 0, size);
  std::memcpy(dst, text.data(), std::min(text.size(), size - 1));
}

// The ioctls Device::ioctl answers (the rest are ENOTTY).
bool handles(unsigned long request) {
  static constexpr unsigned long kHandled[] = {
      VIDIOC_QUERYCAP, VIDIOC_ENUM_FMT, VIDIOC_ENUM_FRAMESIZES, VIDIOC_ENUM_FRAMEINTERVALS, VIDIOC_G_FMT,
      VIDIOC_TRY_FMT, VIDIOC_S_FMT, VIDIOC_G_PARM, VIDIOC_S_PARM, VIDIOC_ENUMINPUT, VIDIOC_G_INPUT, VIDIOC_S_INPUT,
      VIDIOC_REQBUFS, VIDIOC_QUERYBUF, VIDIOC_QBUF, VIDIOC_DQBUF, VIDIOC_STREAMON, VIDIOC_STREAMOFF,
      VIDIOC_QUERYCTRL, VIDIOC_QUERY_EXT_CTRL, VIDIOC_QUERYMENU, VIDIOC_G_CTRL, VIDIOC_S_CTRL,
      VIDIOC_G_EXT_CTRLS, VIDIOC_S_EXT_CTRLS, VIDIOC_TRY_EXT_CTRLS, VIDIOC_SUBSCRIBE_EVENT,
      VIDIOC_UNSUBSCRIBE_EVENT, VIDIOC_DQEVENT};
  return std::find(std::begin(kHandled), std::end(kHandled), request) != std::end(kHandled);
}

}  // namespace

int64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

bool blocking_file(const OpenFile& file) {
  const int flags = ::fcntl(file.fd, F_GETFL);  // follows F_SETFL changes the host makes
  return flags >= 0 && (flags & O_NONBLOCK) == 0;
}

Device::Device(DeviceConfig config)
    : config_(std::move(config)),
      type_(config_.buffer_type == BufferType::Mplane ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE),
      source_(config_),
      controls_(config_.gain_unity, source_.metadata(0), max_digital_gain(source_)),
      faults_(config_.faults) {}

Device::~Device() { free_buffers(); }

bool Device::present(int64_t now) {
  if (unplugged_ && now >= replug_at_) unplugged_ = false;
  return !unplugged_;
}

void Device::attach(OpenFile& file) {
  files_.push_back(&file);
  ++open_count_;
  ++stats.opens;
}

void Device::detach(OpenFile& file) {
  --open_count_;
  std::erase(files_, &file);
  if (owner_ == &file) {  // vb2_fop_release: the owner's close stops the stream and frees the queue
    stop_streaming();
    free_buffers();
  }
}

void Device::disconnect_all() {
  for (OpenFile* f : files_) f->dead = true;
  files_.clear();
  stop_streaming();
  free_buffers();
}

// ---- The schedule ------------------------------------------------------------------------------

int64_t Device::recorded_offset(uint64_t g) const {
  const size_t n = source_.frame_count();
  const int64_t period = source_.exposure_end_ns(n - 1) - source_.exposure_end_ns(0) + source_.interval_ns();
  return int64_t(g / n) * period + source_.exposure_end_ns(g % n) - source_.exposure_end_ns(0);
}

int64_t Device::timestamp(uint64_t g) const {
  const size_t i = g % source_.frame_count();
  const FrameMetadata& m = source_.metadata(i);
  const int64_t loop_shift = recorded_offset(g) - (source_.exposure_end_ns(i) - source_.exposure_end_ns(0));
  int64_t t = (config_.timestamp_source == TimestampSource::StartOfExposure ? m.exposure_start_ns
                                                                             : source_.exposure_end_ns(i)) + loop_shift;
  if (config_.timestamps == TimestampBase::Live) t += anchor_ns_ + shift_ns_ - source_.exposure_end_ns(0);
  return t;
}

int64_t Device::next_wake(int64_t now) const {
  if (unplugged_) return replug_at_;
  if (!streaming_ || !has_frame(next_)) return kNever;
  if (config_.pacing == Pacing::Realtime) return due(next_);
  return queued_.empty() ? kNever : std::max(now, fast_hold_until_);
}

void Device::advance(int64_t now) {
  if (unplugged_) return;
  while (streaming_ && has_frame(next_)) {
    int64_t at = now;
    if (config_.pacing == Pacing::Realtime) {
      at = due(next_);
      if (at > now) break;
    } else if (queued_.empty() || now < fast_hold_until_) {
      break;
    }
    bool moved = false;  // a stall or drop changed which frame is due, or when
    for (const Fault& fault : faults_.take(next_ % source_.frame_count())) {
      switch (fault.kind) {
        case FaultKind::Unplug:
          unplug(at, fault.replug_after_ns);
          return;
        case FaultKind::Stall:
          shift_ns_ += fault.duration_ns;
          if (config_.pacing == Pacing::Fast) fast_hold_until_ = at + fault.duration_ns;
          moved = true;
          break;
        case FaultKind::Drop:
          for (uint32_t k = 0; k < fault.count && has_frame(next_); ++k) {
            ++sequence_;  // lost on the way: the sequence still counts it
            ++next_;
            ++stats.frames_skipped_by_fault;
          }
          moved = true;
          break;
        case FaultKind::ErrorBuffer: error_frame_ = next_; break;
        case FaultKind::Eagain: spurious_ += fault.count; break;
        case FaultKind::Eio: eio_ = true; break;
      }
      if (moved) break;  // the rest of this frame's faults (if any) wait for it to fall due again
    }
    if (moved) continue;
    deliver(next_, at);
  }
}

void Device::deliver(uint64_t g, int64_t at) {
  const size_t i = g % source_.frame_count();
  // Controls (and their events) first: a client that reads events before the buffer sees the
  // values that belong to it.
  std::vector<ControlChange> changes;
  controls_.follow(source_.metadata(i), changes);
  queue_control_events(changes, nullptr, at);
  if (queued_.empty()) {
    ++stats.frames_dropped_no_buffer;
  } else {
    const uint32_t index = queued_.front();
    queued_.pop_front();
    Buffer& b = buffers_[index];
    const OfferedFormat& f = source_.formats()[format_];
    uint8_t* buffer = memory_ + size_t(index) * buffer_stride_;
    if (num_planes_ == 1) {
      b.bytes_used = uint32_t(source_.render(i, f, buffer, plane_length_[0]));
    } else {
      scratch_.resize(f.size_image);
      b.bytes_used = uint32_t(source_.render(i, f, scratch_.data(), scratch_.size()));
      size_t at = 0;
      for (uint32_t p = 0; p < num_planes_ && b.bytes_used == f.size_image; ++p) {
        std::memcpy(buffer + plane_offset_[p], scratch_.data() + at, plane_length_[p]);
        at += plane_length_[p];
      }
    }
    b.sequence = sequence_;
    b.timestamp_ns = timestamp(g);
    b.error = error_frame_ == g || b.bytes_used == 0;
    b.queued = false;
    b.done = true;
    done_.push_back(index);
    ++stats.frames_delivered;
    if (b.error) ++stats.error_buffers;
  }
  ++sequence_;
  next_ = g + 1;
}

void Device::unplug(int64_t at, int64_t replug_after_ns) {
  ++stats.unplugs;
  unplugged_ = true;
  replug_at_ = replug_after_ns < 0 ? kNever : at + replug_after_ns;
  ++next_;  // the frame that was about to fall due is lost with the camera
  const uint64_t next = next_;
  disconnect_all();
  next_ = next;
  resume_ = true;
}

void Device::stop_streaming() {
  streaming_ = false;
  queued_.clear();
  done_.clear();
  for (Buffer& b : buffers_) {
    b.queued = b.done = b.error = false;
    b.bytes_used = 0;
  }
  next_ = 0;
  resume_ = false;
  spurious_ = 0;
  eio_ = false;
}

void Device::free_buffers() {
  if (memory_ != nullptr) ::munmap(memory_, buffer_stride_ * buffers_.size());
  if (memfd_ >= 0) ::close(memfd_);  // the host's mappings keep the memory (orphaned buffers)
  memory_ = nullptr;
  memfd_ = -1;
  buffers_.clear();
  queued_.clear();
  done_.clear();
  owner_ = nullptr;
}

void Device::queue_control_events(const std::vector<ControlChange>& changes, const OpenFile* setter, int64_t at) {
  for (const ControlChange& change : changes) {
    v4l2_event e{};
    e.type = V4L2_EVENT_CTRL;
    e.id = change.id;
    controls_.fill_event(change.id, change.changes, e.u.ctrl);
    e.timestamp.tv_sec = at / 1000000000;
    e.timestamp.tv_nsec = at % 1000000000;
    for (OpenFile* f : files_) {
      // The setter hears of its own value change only with V4L2_EVENT_SUB_FL_ALLOW_FEEDBACK.
      if (f == setter && change.changes == V4L2_EVENT_CTRL_CH_VALUE &&
          (f->events.flags(V4L2_EVENT_CTRL, change.id) & V4L2_EVENT_SUB_FL_ALLOW_FEEDBACK) == 0)
        continue;
      if (f->events.queue(e)) ++stats.control_events;
    }
  }
}

// ---- ioctls ------------------------------------------------------------------------------------

int Device::ioctl(OpenFile& file, unsigned long request, void* arg, const Waiter& wait) {
  // The v4l2 core refuses an ioctl the device lacks (ENOTTY) before it looks at the argument.
  if (arg == nullptr) return handles(request) ? EFAULT : ENOTTY;
  switch (request) {
    case VIDIOC_QUERYCAP: return querycap(*static_cast<v4l2_capability*>(arg));
    case VIDIOC_ENUM_FMT: return enum_fmt(*static_cast<v4l2_fmtdesc*>(arg));
    case VIDIOC_ENUM_FRAMESIZES: return enum_framesizes(*static_cast<v4l2_frmsizeenum*>(arg));
    case VIDIOC_ENUM_FRAMEINTERVALS: return enum_frameintervals(*static_cast<v4l2_frmivalenum*>(arg));
    case VIDIOC_G_FMT: {
      auto& f = *static_cast<v4l2_format*>(arg);
      if (f.type != type_) return EINVAL;
      fill_format(format_, f);
      return 0;
    }
    case VIDIOC_TRY_FMT:
    case VIDIOC_S_FMT: {
      auto& f = *static_cast<v4l2_format*>(arg);
      if (f.type != type_) return EINVAL;
      if (request == VIDIOC_S_FMT) {
        if (busy(file) || !buffers_.empty()) return EBUSY;  // uvcvideo: EBUSY while buffers are allocated
        format_ = adjust_format(f);
      }
      fill_format(adjust_format(f), f);
      return 0;
    }
    case VIDIOC_G_PARM: return parm(*static_cast<v4l2_streamparm*>(arg));
    case VIDIOC_S_PARM: {
      auto& p = *static_cast<v4l2_streamparm*>(arg);
      if (p.type != type_) return EINVAL;
      if (busy(file) || streaming_) return EBUSY;  // as uvcvideo
      return parm(p);  // one interval: every request gets it
    }
    case VIDIOC_ENUMINPUT: {
      auto& in = *static_cast<v4l2_input*>(arg);
      if (in.index != 0) return EINVAL;
      std::memset(&in, 0, sizeof in);
      copy_name(in.name, sizeof in.name, "Camera 1");
      in.type = V4L2_INPUT_TYPE_CAMERA;
      return 0;
    }
    case VIDIOC_G_INPUT: *static_cast<int*>(arg) = 0; return 0;
    case VIDIOC_S_INPUT:
      if (*static_cast<int*>(arg) != 0) return EINVAL;
      return busy(file) ? EBUSY : 0;
    case VIDIOC_REQBUFS: return reqbufs(file, *static_cast<v4l2_requestbuffers*>(arg));
    case VIDIOC_QUERYBUF: {
      auto& b = *static_cast<v4l2_buffer*>(arg);
      if (b.type != type_ || b.index >= buffers_.size()) return EINVAL;
      if (mplane() && (b.m.planes == nullptr || b.length < num_planes_)) return EINVAL;
      fill_buffer(b.index, b);
      return 0;
    }
    case VIDIOC_QBUF: return qbuf(file, *static_cast<v4l2_buffer*>(arg));
    case VIDIOC_DQBUF: return dqbuf(file, *static_cast<v4l2_buffer*>(arg), wait);
    case VIDIOC_STREAMON: {
      if (*static_cast<int*>(arg) != int(type_)) return EINVAL;
      return streamon(file, monotonic_ns());
    }
    case VIDIOC_STREAMOFF: {
      if (*static_cast<int*>(arg) != int(type_)) return EINVAL;
      if (busy(file)) return EBUSY;
      stop_streaming();  // every buffer back to userspace, done ones cleared; the next STREAMON starts at frame 0
      return 0;
    }
    case VIDIOC_QUERYCTRL: return controls_.query(*static_cast<v4l2_queryctrl*>(arg));
    case VIDIOC_QUERY_EXT_CTRL: return controls_.query_ext(*static_cast<v4l2_query_ext_ctrl*>(arg));
    case VIDIOC_QUERYMENU: return controls_.query_menu(*static_cast<v4l2_querymenu*>(arg));
    case VIDIOC_G_CTRL: {
      auto& c = *static_cast<v4l2_control*>(arg);
      return controls_.get(c.id, c.value);
    }
    case VIDIOC_S_CTRL: {
      auto& c = *static_cast<v4l2_control*>(arg);
      int32_t value = c.value;
      if (const int err = controls_.check(c.id, value, controls_.value(V4L2_CID_EXPOSURE_AUTO),
                                          controls_.value(V4L2_CID_AUTOGAIN)))
        return err;
      std::vector<ControlChange> changes;
      controls_.set(c.id, value, changes);
      queue_control_events(changes, &file, monotonic_ns());
      c.value = value;
      return 0;
    }
    case VIDIOC_G_EXT_CTRLS:
    case VIDIOC_S_EXT_CTRLS:
    case VIDIOC_TRY_EXT_CTRLS: return ext_ctrls(file, request, *static_cast<v4l2_ext_controls*>(arg));
    case VIDIOC_SUBSCRIBE_EVENT: return subscribe(file, *static_cast<v4l2_event_subscription*>(arg));
    case VIDIOC_UNSUBSCRIBE_EVENT: {
      const auto& s = *static_cast<v4l2_event_subscription*>(arg);
      file.events.unsubscribe(s.type, s.id);
      return 0;
    }
    case VIDIOC_DQEVENT: return dqevent(file, *static_cast<v4l2_event*>(arg), wait);
    default: return ENOTTY;
  }
}

int Device::querycap(v4l2_capability& cap) const {
  std::memset(&cap, 0, sizeof cap);
  copy_name(cap.driver, sizeof cap.driver, "arpipe-standin");
  copy_name(cap.card, sizeof cap.card, config_.card);
  copy_name(cap.bus_info, sizeof cap.bus_info, config_.bus_info);
  cap.version = LINUX_VERSION_CODE;  // what the kernel's v4l2 core reports
  cap.device_caps = (mplane() ? V4L2_CAP_VIDEO_CAPTURE_MPLANE : V4L2_CAP_VIDEO_CAPTURE) | V4L2_CAP_STREAMING |
                    V4L2_CAP_EXT_PIX_FORMAT;
  cap.capabilities = cap.device_caps | V4L2_CAP_DEVICE_CAPS;
  return 0;
}

int Device::enum_fmt(v4l2_fmtdesc& desc) const {
  if (desc.type != type_ || desc.index >= source_.formats().size()) return EINVAL;
  const OfferedFormat& f = source_.formats()[desc.index];
  const uint32_t index = desc.index;
  std::memset(&desc, 0, sizeof desc);
  desc.index = index;
  desc.type = type_;
  desc.flags = f.fourcc == V4L2_PIX_FMT_MJPEG ? V4L2_FMT_FLAG_COMPRESSED : 0;
  copy_name(desc.description, sizeof desc.description, f.description);
  desc.pixelformat = f.fourcc;
  return 0;
}

int Device::enum_framesizes(v4l2_frmsizeenum& e) const {
  const auto& formats = source_.formats();
  const bool offered = std::any_of(formats.begin(), formats.end(), [&](const OfferedFormat& f) { return f.fourcc == e.pixel_format; });
  if (!offered || e.index != 0) return EINVAL;
  const uint32_t pixel_format = e.pixel_format;
  std::memset(&e, 0, sizeof e);
  e.pixel_format = pixel_format;
  e.type = V4L2_FRMSIZE_TYPE_DISCRETE;
  e.discrete.width = uint32_t(source_.width());
  e.discrete.height = uint32_t(source_.height());
  return 0;
}

int Device::enum_frameintervals(v4l2_frmivalenum& e) const {
  const auto& formats = source_.formats();
  const bool offered = std::any_of(formats.begin(), formats.end(), [&](const OfferedFormat& f) { return f.fourcc == e.pixel_format; });
  if (!offered || e.index != 0 || e.width != uint32_t(source_.width()) || e.height != uint32_t(source_.height())) return EINVAL;
  const v4l2_frmivalenum in = e;
  std::memset(&e, 0, sizeof e);
  e.pixel_format = in.pixel_format;
  e.width = in.width;
  e.height = in.height;
  e.type = V4L2_FRMIVAL_TYPE_DISCRETE;
  const int64_t gcd = std::gcd(source_.interval_ns(), int64_t(1000000000));
  e.discrete.numerator = uint32_t(source_.interval_ns() / gcd);
  e.discrete.denominator = uint32_t(1000000000 / gcd);
  return 0;
}

size_t Device::adjust_format(const v4l2_format& f) const {
  const auto& formats = source_.formats();
  for (size_t i = 0; i < formats.size(); ++i)
    if (formats[i].fourcc == f.fmt.pix.pixelformat) return i;
  return 0;  // an unknown format becomes the first offered, as drivers do
}

void Device::fill_format(size_t index, v4l2_format& f) const {
  const OfferedFormat& o = source_.formats()[index];
  std::memset(&f.fmt, 0, sizeof f.fmt);
  f.type = type_;
  if (mplane()) {
    v4l2_pix_format_mplane& m = f.fmt.pix_mp;
    m.width = uint32_t(source_.width());
    m.height = uint32_t(source_.height());
    m.pixelformat = o.fourcc;
    m.field = V4L2_FIELD_NONE;
    m.colorspace = o.colorspace;
    m.num_planes = uint8_t(o.num_planes);
    for (uint32_t i = 0; i < o.num_planes; ++i) {
      m.plane_fmt[i].bytesperline = o.plane_bytes_per_line[i];
      m.plane_fmt[i].sizeimage = o.plane_size[i];
    }
    m.ycbcr_enc = uint8_t(o.ycbcr_enc);
    m.quantization = uint8_t(o.quantization);
    m.xfer_func = uint8_t(o.xfer_func);
    return;
  }
  v4l2_pix_format& p = f.fmt.pix;
  p.width = uint32_t(source_.width());
  p.height = uint32_t(source_.height());
  p.pixelformat = o.fourcc;
  p.field = V4L2_FIELD_NONE;
  p.bytesperline = o.bytes_per_line;
  p.sizeimage = o.size_image;
  p.colorspace = o.colorspace;
  p.priv = V4L2_PIX_FMT_PRIV_MAGIC;  // set by the v4l2 core for every driver
  p.ycbcr_enc = o.ycbcr_enc;
  p.quantization = o.quantization;
  p.xfer_func = o.xfer_func;
}

int Device::parm(v4l2_streamparm& p) const {
  if (p.type != type_) return EINVAL;
  std::memset(&p.parm, 0, sizeof p.parm);
  p.parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
  const int64_t gcd = std::gcd(source_.interval_ns(), int64_t(1000000000));
  p.parm.capture.timeperframe.numerator = uint32_t(source_.interval_ns() / gcd);
  p.parm.capture.timeperframe.denominator = uint32_t(1000000000 / gcd);
  return 0;
}

int Device::reqbufs(OpenFile& file, v4l2_requestbuffers& r) {
  r.capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP | V4L2_BUF_CAP_SUPPORTS_ORPHANED_BUFS;  // filled even on errors (vb2)
  if (r.type != type_ || r.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file) || streaming_) return EBUSY;
  r.flags = 0;
  std::memset(r.reserved, 0, sizeof r.reserved);
  free_buffers();
  if (r.count == 0) return 0;
  const uint32_t count = std::clamp<uint32_t>(r.count, 1, kMaxBuffers);
  const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  const OfferedFormat& format = source_.formats()[format_];
  buffer_length_ = format.size_image;
  num_planes_ = mplane() ? format.num_planes : 1;
  buffer_stride_ = 0;
  for (uint32_t i = 0; i < num_planes_; ++i) {
    plane_length_[i] = mplane() ? format.plane_size[i] : format.size_image;
    plane_offset_[i] = buffer_stride_;
    buffer_stride_ += (plane_length_[i] + page - 1) / page * page;
  }
  memfd_ = ::memfd_create("arpipe-v4l2-standin", MFD_CLOEXEC);
  if (memfd_ < 0) return ENOMEM;
  if (::ftruncate(memfd_, off_t(buffer_stride_ * count)) != 0) {
    free_buffers();
    return ENOMEM;
  }
  void* p = ::mmap(nullptr, buffer_stride_ * count, PROT_READ | PROT_WRITE, MAP_SHARED, memfd_, 0);
  if (p == MAP_FAILED) {
    free_buffers();
    return ENOMEM;
  }
  memory_ = static_cast<uint8_t*>(p);
  buffers_.assign(count, Buffer{});
  owner_ = &file;
  r.count = count;
  return 0;
}

void Device::fill_buffer(uint32_t index, v4l2_buffer& b) const {
  const Buffer& s = buffers_[index];
  v4l2_plane* planes = mplane() ? b.m.planes : nullptr;  // the caller's array, checked by the caller
  std::memset(&b, 0, sizeof b);
  b.index = index;
  b.type = type_;
  b.memory = V4L2_MEMORY_MMAP;
  if (planes != nullptr) {
    b.m.planes = planes;
    b.length = num_planes_;
    for (uint32_t i = 0; i < num_planes_; ++i) {
      std::memset(&planes[i], 0, sizeof planes[i]);
      planes[i].length = plane_length_[i];
      planes[i].m.mem_offset = uint32_t(size_t(index) * buffer_stride_ + plane_offset_[i]);
      planes[i].bytesused = plane_bytes_used(s, i);
      planes[i].data_offset = 0;
    }
  } else {
    b.m.offset = uint32_t(size_t(index) * buffer_stride_);
    b.length = buffer_length_;
  }
  b.field = V4L2_FIELD_NONE;
  b.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC |
            (config_.timestamp_source == TimestampSource::StartOfExposure ? V4L2_BUF_FLAG_TSTAMP_SRC_SOE
                                                                          : V4L2_BUF_FLAG_TSTAMP_SRC_EOF);
  if (s.mapped) b.flags |= V4L2_BUF_FLAG_MAPPED;
  if (s.queued) b.flags |= V4L2_BUF_FLAG_QUEUED;
  if (s.done) b.flags |= V4L2_BUF_FLAG_DONE;
  if (s.error) b.flags |= V4L2_BUF_FLAG_ERROR;
  if (s.done || s.error || s.bytes_used > 0) {
    b.bytesused = s.bytes_used;
    b.sequence = s.sequence;
    // timeval as vb2 converts (ns_to_timeval: whole microseconds, rounded down).
    const int64_t us = s.timestamp_ns >= 0 ? s.timestamp_ns / 1000 : -((-s.timestamp_ns + 999) / 1000);
    b.timestamp.tv_sec = us >= 0 ? us / 1000000 : -((-us + 999999) / 1000000);
    b.timestamp.tv_usec = us - int64_t(b.timestamp.tv_sec) * 1000000;
  }
}

uint32_t Device::plane_bytes_used(const Buffer& b, uint32_t plane) const {
  if (num_planes_ == 1) return b.bytes_used;
  return b.bytes_used == 0 ? 0 : plane_length_[plane];  // a split frame fills every plane whole
}

int Device::qbuf(OpenFile& file, v4l2_buffer& b) {
  if (b.type != type_ || b.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file)) return EBUSY;
  if (b.index >= buffers_.size()) return EINVAL;
  if (mplane() && (b.m.planes == nullptr || b.length < num_planes_)) return EINVAL;  // vb2: too few planes
  Buffer& s = buffers_[b.index];
  if (s.queued || s.done) return EINVAL;  // vb2: the buffer is not in dequeued state
  s = Buffer{false, false, s.mapped, false, 0, 0, 0};
  s.queued = true;
  queued_.push_back(b.index);
  fill_buffer(b.index, b);
  advance(monotonic_ns());  // fast pacing: a queued buffer lets the next frame fall due now (or a fault fire)
  return 0;
}

int Device::dqbuf(OpenFile& file, v4l2_buffer& b, const Waiter& wait) {
  if (b.type != type_ || b.memory != V4L2_MEMORY_MMAP) return EINVAL;
  if (busy(file)) return EBUSY;
  if (mplane() && (b.m.planes == nullptr || b.length < num_planes_)) return EINVAL;
  const bool may_block = blocking_file(file);
  for (;;) {
    if (file.dead) return EIO;  // vb2 after a disconnect while waiting: the queue is in error state
    if (!streaming_) return EINVAL;
    if (eio_) {
      eio_ = false;
      return EIO;
    }
    if (spurious_ > 0) {
      --spurious_;
      return EAGAIN;
    }
    if (!done_.empty()) {
      const uint32_t index = done_.front();
      done_.pop_front();
      buffers_[index].done = false;
      fill_buffer(index, b);
      return 0;
    }
    if (!may_block) return EAGAIN;
    const int64_t now = monotonic_ns();
    wait(next_wake(now));
    advance(monotonic_ns());
  }
}

int Device::streamon(OpenFile& file, int64_t now) {
  if (busy(file)) return EBUSY;
  if (buffers_.empty()) return EINVAL;  // vb2: no buffers have been allocated
  if (streaming_) return 0;
  streaming_ = true;
  ++stats.streamons;
  sequence_ = 0;
  spurious_ = 0;
  eio_ = false;
  if (resume_) {
    // Back after an unplug: the realtime schedule kept running, frames due while the camera was
    // away are lost; fast pacing continues with the next frame.
    resume_ = false;
    if (config_.pacing == Pacing::Realtime)
      while (has_frame(next_) && due(next_) < now) ++next_;
  } else {
    anchor_ns_ = now;
    shift_ns_ = 0;
    fast_hold_until_ = 0;
    next_ = 0;
    error_frame_ = UINT64_MAX;
  }
  advance(now);
  return 0;
}

int Device::ext_ctrls(OpenFile& file, unsigned long request, v4l2_ext_controls& c) {
  const bool get = request == VIDIOC_G_EXT_CTRLS, set = request == VIDIOC_S_EXT_CTRLS;
  const uint32_t which = c.which;
  const bool class_which = which != V4L2_CTRL_WHICH_CUR_VAL && which != V4L2_CTRL_WHICH_DEF_VAL;
  if (which == V4L2_CTRL_WHICH_REQUEST_VAL || (which == V4L2_CTRL_WHICH_DEF_VAL && !get)) return EINVAL;
  if (c.count == 0) {  // a class check only
    if (!class_which) return 0;
    v4l2_query_ext_ctrl q{};
    q.id = (which - 1) | V4L2_CTRL_FLAG_NEXT_CTRL;  // the first control at or after the class base
    return controls_.query_ext(q) == 0 && V4L2_CTRL_ID2WHICH(q.id) == which ? 0 : EINVAL;
  }
  if (c.controls == nullptr) return EFAULT;
  // Validation: G and TRY name the failing control; S names none (error_idx = count).
  const auto fail = [&](uint32_t i, int err) {
    c.error_idx = set ? c.count : i;
    return err;
  };
  int32_t auto_exposure = controls_.value(V4L2_CID_EXPOSURE_AUTO), auto_gain = controls_.value(V4L2_CID_AUTOGAIN);
  for (uint32_t i = 0; i < c.count && !get; ++i) {  // a mode set in the same call governs its partner
    if (c.controls[i].id == V4L2_CID_EXPOSURE_AUTO) auto_exposure = c.controls[i].value;
    if (c.controls[i].id == V4L2_CID_AUTOGAIN) auto_gain = c.controls[i].value != 0;
  }
  std::vector<int32_t> values(c.count);
  for (uint32_t i = 0; i < c.count; ++i) {
    v4l2_ext_control& x = c.controls[i];
    if (!controls_.exists(x.id) || (class_which && V4L2_CTRL_ID2WHICH(x.id) != which)) return fail(i, EINVAL);
    if (get) continue;
    values[i] = x.value;
    if (const int err = controls_.check(x.id, values[i], auto_exposure, auto_gain)) return fail(i, err);
  }
  std::vector<ControlChange> changes;
  for (uint32_t i = 0; i < c.count; ++i) {
    v4l2_ext_control& x = c.controls[i];
    if (get) {
      int32_t v = 0;  // x.value is a packed field
      if (which == V4L2_CTRL_WHICH_DEF_VAL)
        controls_.get_default(x.id, v);
      else
        controls_.get(x.id, v);
      x.value = v;
      continue;
    }
    x.value = values[i];
    if (set) controls_.set(x.id, values[i], changes);
  }
  if (set) queue_control_events(changes, &file, monotonic_ns());
  return 0;
}

int Device::subscribe(OpenFile& file, const v4l2_event_subscription& s) {
  if (s.type != V4L2_EVENT_CTRL || !controls_.exists(s.id)) return EINVAL;  // uvcvideo: control events only
  if (file.events.subscribed(s.type, s.id)) return 0;
  file.events.subscribe(s.type, s.id, s.flags);
  if (s.flags & V4L2_EVENT_SUB_FL_SEND_INITIAL) {
    v4l2_event e{};
    e.type = V4L2_EVENT_CTRL;
    e.id = s.id;
    controls_.fill_event(s.id, V4L2_EVENT_CTRL_CH_VALUE | V4L2_EVENT_CTRL_CH_FLAGS, e.u.ctrl);
    const int64_t now = monotonic_ns();
    e.timestamp.tv_sec = now / 1000000000;
    e.timestamp.tv_nsec = now % 1000000000;
    if (file.events.queue(e)) ++stats.control_events;
  }
  return 0;
}

int Device::dqevent(OpenFile& file, v4l2_event& e, const Waiter& wait) {
  const bool may_block = blocking_file(file);
  for (;;) {
    if (file.dead) return ENODEV;
    if (file.events.dequeue(e)) return 0;
    if (!may_block) return ENOENT;
    // A blocking file handle waits for an event, as v4l2_event_dequeue does.
    wait(next_wake(monotonic_ns()));
    advance(monotonic_ns());
  }
}

short Device::poll_events(const OpenFile& file, short requested) const {
  if (file.dead) return POLLERR | POLLHUP;
  short r = 0;
  if (file.events.pending()) r |= POLLPRI;
  if (requested & (POLLIN | POLLRDNORM)) {
    if (!streaming_)
      r |= POLLERR;  // vb2: nothing to wait for
    else if (!done_.empty() || spurious_ > 0)
      r |= POLLIN | POLLRDNORM;
  }
  return short(r & (requested | POLLERR | POLLHUP));
}

void* Device::mmap(void* addr, size_t length, int prot, int flags, int64_t offset) {
  const auto fail = [](int err) {
    errno = err;
    return MAP_FAILED;
  };
  if ((flags & MAP_SHARED) == 0 || (prot & PROT_READ) == 0) return fail(EINVAL);  // vb2 capture queues
  if (buffers_.empty() || offset < 0) return fail(EINVAL);
  const size_t index = size_t(offset) / buffer_stride_, within = size_t(offset) % buffer_stride_;
  const size_t page = size_t(::sysconf(_SC_PAGESIZE));
  uint32_t plane = 0;  // each plane is mapped by its own offset, as vb2 gives it
  while (plane < num_planes_ && plane_offset_[plane] != within) ++plane;
  if (index >= buffers_.size() || plane == num_planes_ || length == 0 ||
      length > (plane_length_[plane] + page - 1) / page * page)
    return fail(EINVAL);
  void* p = ::mmap(addr, length, prot, flags, memfd_, off_t(offset));
  if (p == MAP_FAILED) return p;
  buffers_[index].mapped = true;
  return p;
}

}  // namespace arpipe::standin
