#include "capture/v4l2/v4l2_stream.h"

#include <linux/videodev2.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <optional>

#include <fmt/format.h>

#include "capture/v4l2/mjpeg_decoder.h"
#include "capture/v4l2/v4l2_device.h"
#include "capture/v4l2/v4l2_frame_layout.h"
#include "capture/v4l2/v4l2_mmap_buffers.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

V4L2StreamSettings v4l2_stream_settings(const SourceConfig& config) {
  V4L2StreamSettings s;
  s.device = config.device;
  s.request = {config.width, config.height, config.fps, config.pixel_format};
  s.buffers = uint32_t(config.buffers);
  s.exposure = {config.exposure_us, config.gain, config.gain_unity};
  s.timestamp_meaning = config.timestamp_meaning;
  s.readout_ns = config.readout_ns;
  s.timestamp_offset_ns = config.timestamp_offset_ns;
  return s;
}

namespace {

int64_t timeval_ns(const timeval& tv) { return int64_t(tv.tv_sec) * 1'000'000'000 + int64_t(tv.tv_usec) * 1000; }

// The driver's TSTAMP_SRC flag, unless the config overrides it (drivers disagree with their flags).
TimestampMeaning timestamp_meaning(uint32_t flags, BufferTimestamps configured) {
  if (const auto fixed = fixed_timestamp_meaning(configured)) return *fixed;
  return (flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE ? TimestampMeaning::StartOfExposure
                                                                                 : TimestampMeaning::EndOfFrame;
}

// "UYVY", "NV12M": the config's name for the camera's format, else its FourCC.
std::string describe_layout(const V4L2FrameLayout& layout, uint32_t fourcc) {
  if (layout.name != CaptureFormat::Auto) return std::string(choice_name(kCaptureFormatNames, layout.name));
  return fourcc_text(fourcc);
}

// The status for a failed DQBUF or a poll error: a vanished or broken device is Gone (the source
// reopens it); EAGAIN is a spurious wake-up.
StreamStatus dequeue_failure(int err, const std::string& path, std::string& why) {
  why = fmt::format("{}: VIDIOC_DQBUF: {}", path, std::strerror(err));
  return err == EAGAIN ? StreamStatus::Again : StreamStatus::Gone;
}

class V4L2Stream final : public CameraStream {
 public:
  explicit V4L2Stream(const V4L2StreamSettings& settings) : settings_(settings), device_(settings.device) {
    if (!device_.can_capture())
      throw CameraError(CameraError::Kind::Refused,
                        fmt::format("{}: '{}' is not a video capture device with streaming I/O (device caps {:#x})",
                                    settings.device, device_.card(), device_.device_caps()));
    const auto offers = device_.enumerate_formats();
    const V4L2FormatChoice choice = choose_v4l2_format(offers, settings.request, settings.device);
    set_format(choice, offers);
    if (choice.interval) set_interval(*choice.interval, offers);
    read_interval();
    controls_.emplace(device_, settings.exposure);
    buffers_.emplace(device_, settings.buffers, memory_planes_);
    for (uint32_t i = 0; i < buffers_->count(); ++i)
      if (const int err = buffers_->queue(i); err != 0) fail("VIDIOC_QBUF", err);
    wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (wake_fd_ < 0) fail("eventfd", errno);
    int type = int(device_.buffer_type());
    if (const int err = device_.ioctl(VIDIOC_STREAMON, &type); err != 0) {
      ::close(wake_fd_);
      fail("VIDIOC_STREAMON", err);
    }
    streaming_ = true;
    log::info("{}: streaming {}; {}", describe(), describe_format(), controls_->describe());
  }

  ~V4L2Stream() override {
    if (streaming_) {
      int type = int(device_.buffer_type());
      device_.ioctl(VIDIOC_STREAMOFF, &type);
    }
    buffers_.reset();  // before the device closes
    if (wake_fd_ >= 0) ::close(wake_fd_);
  }

  std::string describe() const override {
    return fmt::format("v4l2:{} ({}, {})", describe_device_path(settings_.device), device_.card(), device_.bus_info());
  }
  const StreamFormat& format() const override { return format_; }
  StreamCounters counters() const override {
    std::lock_guard lock(counters_mutex_);
    return counters_;
  }
  void interrupt() override {
    const uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
  }

  StreamStatus next(Frame& frame, int64_t timeout_ns, std::string& why) override {
    const int64_t deadline = monotonic_now_ns() + timeout_ns;
    for (;;) {
      const int64_t left_ms = std::max<int64_t>(0, (deadline - monotonic_now_ns() + 999'999) / 1'000'000);
      pollfd fds[2] = {{device_.fd(), POLLIN | POLLPRI, 0}, {wake_fd_, POLLIN, 0}};
      const int ready = ::poll(fds, 2, int(std::min<int64_t>(left_ms, 60'000)));
      if (ready < 0) {
        if (errno == EINTR) continue;
        why = fmt::format("{}: poll: {}", settings_.device, std::strerror(errno));
        return StreamStatus::Gone;
      }
      if (fds[1].revents & POLLIN) {
        uint64_t count = 0;
        [[maybe_unused]] const ssize_t n = ::read(wake_fd_, &count, sizeof count);
        why = "interrupted";
        return StreamStatus::Interrupted;
      }
      if (ready == 0) {
        if (monotonic_now_ns() < deadline) continue;
        count([](StreamCounters& c) { ++c.timeouts; });
        why = fmt::format("{}: no frame within {:.0f} ms", settings_.device, double(timeout_ns) * 1e-6);
        return StreamStatus::Timeout;
      }
      const short revents = fds[0].revents;
      // Events first: a control change is queued before the frame it belongs to. V4L2 ties no
      // event to a frame, so this is exact while each frame is dequeued before the next completes;
      // a reader that falls k frames behind gives those frames values up to k frames early.
      if (revents & POLLPRI) {
        const int events = controls_->drain_events();
        count([&](StreamCounters& c) { c.control_events += uint64_t(events); });
      }
      if (revents & POLLIN) return dequeue(frame, why);
      if (revents & (POLLERR | POLLHUP | POLLNVAL)) {
        why = fmt::format("{}: the device reports an error (poll {:#x}); it may have been unplugged", settings_.device,
                          unsigned(revents));
        return StreamStatus::Gone;
      }
    }
  }

 private:
  [[noreturn]] void fail(const char* what, int err) const {
    throw CameraError(err == ENODEV ? CameraError::Kind::Missing : CameraError::Kind::Failed,
                      fmt::format("{}: {}: {}", settings_.device, what, std::strerror(err)));
  }

  void set_format(const V4L2FormatChoice& choice, const std::vector<V4L2FormatOffer>& offers) {
    const bool mplane = device_.multi_planar();
    v4l2_format f{};
    f.type = device_.buffer_type();
    if (mplane) {
      f.fmt.pix_mp.pixelformat = choice.fourcc;
      f.fmt.pix_mp.width = choice.width;
      f.fmt.pix_mp.height = choice.height;
      f.fmt.pix_mp.field = V4L2_FIELD_NONE;
    } else {
      f.fmt.pix.pixelformat = choice.fourcc;
      f.fmt.pix.width = choice.width;
      f.fmt.pix.height = choice.height;
      f.fmt.pix.field = V4L2_FIELD_NONE;
    }
    if (const int err = device_.ioctl(VIDIOC_S_FMT, &f); err != 0) fail("VIDIOC_S_FMT", err);
    const uint32_t got_fourcc = mplane ? f.fmt.pix_mp.pixelformat : f.fmt.pix.pixelformat;
    const uint32_t got_width = mplane ? f.fmt.pix_mp.width : f.fmt.pix.width;
    const uint32_t got_height = mplane ? f.fmt.pix_mp.height : f.fmt.pix.height;
    // Drivers adjust rather than fail: check what they made of it.
    if (got_fourcc != choice.fourcc || got_width != choice.width || got_height != choice.height)
      throw CameraError(CameraError::Kind::Refused,
                        fmt::format("{}: asked for {} {}x{}, the driver set {} {}x{}; the camera offers:\n{}",
                                    settings_.device, fourcc_text(choice.fourcc), choice.width, choice.height,
                                    fourcc_text(got_fourcc), got_width, got_height, describe_v4l2_offers(offers)));
    mjpeg_ = is_mjpeg_fourcc(choice.fourcc);
    if (!mjpeg_) layout_ = *v4l2_frame_layout(choice.fourcc);  // the choice is a usable FourCC
    const uint32_t planes = mplane ? f.fmt.pix_mp.num_planes : 1;
    if (planes < 1 || planes > VIDEO_MAX_PLANES || (!mjpeg_ && planes != uint32_t(layout_.memory_planes)))
      throw CameraError(CameraError::Kind::Refused,
                        fmt::format("{}: the driver gives {} with {} memory planes; arpipe takes it with {}",
                                    settings_.device, fourcc_text(got_fourcc), planes, mjpeg_ ? 1 : layout_.memory_planes));
    memory_planes_ = planes;
    for (uint32_t p = 0; p < planes; ++p)
      bytes_per_line_[p] = mplane ? f.fmt.pix_mp.plane_fmt[p].bytesperline : f.fmt.pix.bytesperline;
    format_.camera_format = mjpeg_ ? "MJPG" : describe_layout(layout_, got_fourcc);
    format_.format = mjpeg_ ? PixelFormat::RGB24 : layout_.frame_format;
    format_.width = int(got_width);
    format_.height = int(got_height);
    if (mjpeg_) decoder_.emplace();
  }

  void set_interval(const V4L2Fraction& interval, const std::vector<V4L2FormatOffer>& offers) {
    v4l2_streamparm parm{};
    parm.type = device_.buffer_type();
    if (device_.ioctl(VIDIOC_G_PARM, &parm) != 0 || !(parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      if (settings_.request.fps > 0)
        throw CameraError(CameraError::Kind::Refused,
                          fmt::format("{}: the driver cannot set the frame rate (no V4L2_CAP_TIMEPERFRAME)",
                                      settings_.device));
      return;
    }
    parm.parm.capture.timeperframe = {interval.numerator, interval.denominator};
    if (const int err = device_.ioctl(VIDIOC_S_PARM, &parm); err != 0) fail("VIDIOC_S_PARM", err);
    const V4L2Fraction got{parm.parm.capture.timeperframe.numerator, parm.parm.capture.timeperframe.denominator};
    if (!same_rate(got.fps(), interval.fps()))
      throw CameraError(CameraError::Kind::Refused,
                        fmt::format("{}: asked for {:.4g} fps, the driver set {:.4g} fps; the camera offers:\n{}",
                                    settings_.device, interval.fps(), got.fps(), describe_v4l2_offers(offers)));
  }

  void read_interval() {
    v4l2_streamparm parm{};
    parm.type = device_.buffer_type();
    if (device_.ioctl(VIDIOC_G_PARM, &parm) == 0 && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      const V4L2Fraction interval{parm.parm.capture.timeperframe.numerator, parm.parm.capture.timeperframe.denominator};
      format_.frame_interval_ns = interval.ns();
    }
  }

  std::string describe_format() const {
    const std::string rate = format_.frame_interval_ns > 0
                                 ? fmt::format(" @ {:.4g} fps", 1e9 / double(format_.frame_interval_ns))
                                 : "";
    const std::string decoded =
        mjpeg_ ? " (decoded to RGB24)"
               : layout_.kind != V4L2FrameLayout::Kind::AsIs
                     ? fmt::format(" (reordered to {} as it is copied)", pixel_format_name(layout_.frame_format))
                     : "";
    const std::string planes =
        device_.multi_planar() ? fmt::format(" of {} plane{}", memory_planes_, memory_planes_ > 1 ? "s" : "") : "";
    // Which path the pixels take: always out of the mapped buffer on the CPU (no dma-buf import,
    // docs/ARCHITECTURE.md), into frame memory the pipeline hands back.
    const char* path = mjpeg_ ? "decoded from the mapped buffer into recycled frames"
                              : "one copy a frame from the mapped buffer into recycled frames";
    return fmt::format("{} {}x{}{}{}, {} {}buffers{} ({})", format_.camera_format, format_.width, format_.height, rate,
                       decoded, buffers_->count(), device_.multi_planar() ? "multi-planar " : "", planes, path);
  }

  template <typename F> void count(F&& update) {
    std::lock_guard lock(counters_mutex_);
    update(counters_);
  }

  StreamStatus dequeue(Frame& frame, std::string& why) {
    v4l2_plane planes[VIDEO_MAX_PLANES] = {};
    v4l2_buffer buffer{};
    buffer.type = device_.buffer_type();
    buffer.memory = V4L2_MEMORY_MMAP;
    if (device_.multi_planar()) {
      buffer.m.planes = planes;
      buffer.length = memory_planes_;
    }
    const int64_t t0 = monotonic_now_ns();
    if (const int err = device_.ioctl(VIDIOC_DQBUF, &buffer); err != 0) {
      if (err == EAGAIN) count([](StreamCounters& c) { ++c.again; });
      return dequeue_failure(err, settings_.device, why);
    }
    const int64_t t1 = monotonic_now_ns();
    const StreamStatus status = take(buffer, frame, why);
    const int64_t t2 = monotonic_now_ns();
    if (const int err = buffers_->queue(buffer.index); err != 0) {
      why = fmt::format("{}: VIDIOC_QBUF: {}", settings_.device, std::strerror(err));
      return StreamStatus::Gone;
    }
    if (status == StreamStatus::Frame) {
      const int64_t t3 = monotonic_now_ns();
      count([&](StreamCounters& c) {
        c.dequeue_ns += (t1 - t0) + (t3 - t2);
        c.convert_ns += t2 - t1;
      });
    }
    return status;
  }

  // Copies (or decodes) the buffer into the frame and fills its metadata.
  StreamStatus take(const v4l2_buffer& buffer, Frame& frame, std::string& why) {
    if (last_sequence_ && buffer.sequence > *last_sequence_ + 1)
      count([&](StreamCounters& c) { c.sequence_gaps += buffer.sequence - *last_sequence_ - 1; });
    last_sequence_ = buffer.sequence;
    if (buffer.flags & V4L2_BUF_FLAG_ERROR) {
      count([](StreamCounters& c) { ++c.error_buffers; });
      why = fmt::format("{}: buffer {} (sequence {}) flagged as corrupt by the driver", settings_.device, buffer.index,
                        buffer.sequence);
      return StreamStatus::Again;
    }
    // Each memory plane as the driver filled it (a multi-planar buffer says per plane, after any
    // data_offset of its own).
    V4L2Plane in[VIDEO_MAX_PLANES];
    for (uint32_t p = 0; p < memory_planes_; ++p) {
      const size_t length = buffers_->length(buffer.index, p);
      size_t used = std::min<size_t>(buffer.bytesused, length), offset = 0;
      if (device_.multi_planar()) {
        used = std::min<size_t>(buffer.m.planes[p].bytesused, length);
        offset = std::min<size_t>(buffer.m.planes[p].data_offset, used);
      }
      in[p] = {buffers_->data(buffer.index, p) + offset, used - offset, bytes_per_line_[p]};
    }
    bool allocated = false, filled = false;
    if (mjpeg_) {
      const size_t capacity = frame.data.capacity();  // grows only by allocating
      filled = decoder_->decode(in[0].data, in[0].bytes_used, format_.width, format_.height, frame, why);
      allocated = frame.data.capacity() > capacity;
    } else {
      filled = fill_frame_from_v4l2(layout_, std::span(in, memory_planes_), format_.width, format_.height, frame,
                                    allocated, why);
    }
    if (!filled) {
      count([](StreamCounters& c) { ++c.error_buffers; });
      why = fmt::format("{}: sequence {}: {}", settings_.device, buffer.sequence, why);
      return StreamStatus::Again;
    }
    if ((buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC && !warned_clock_) {
      log::warn("{}: buffer timestamps are not on CLOCK_MONOTONIC (flags {:#x}); used as they are", settings_.device,
                buffer.flags);
      warned_clock_ = true;
    }
    FrameMetadata& m = frame.meta;
    m = FrameMetadata{};
    m.sequence = buffer.sequence;
    m.exposure_ns = controls_->exposure_ns();
    m.readout_ns = settings_.readout_ns;
    m.frame_duration_ns = format_.frame_interval_ns;
    m.analogue_gain = controls_->analogue_gain();
    m.digital_gain = controls_->digital_gain();
    m.raw_timestamp_ns = timeval_ns(buffer.timestamp);
    m.raw_timestamp_meaning = timestamp_meaning(buffer.flags, settings_.timestamp_meaning);
    m.timestamp_offset_ns = settings_.timestamp_offset_ns;
    m.exposure_start_ns = exposure_start_from_raw(m.raw_timestamp_ns, m.raw_timestamp_meaning, m.exposure_ns,
                                                  m.readout_ns, m.timestamp_offset_ns);
    count([&](StreamCounters& c) {
      ++c.frames;
      c.copies += mjpeg_ ? 0 : 1;
      c.frame_allocations += allocated ? 1 : 0;
    });
    return StreamStatus::Frame;
  }

  V4L2StreamSettings settings_;
  V4L2Device device_;
  StreamFormat format_;
  V4L2FrameLayout layout_;
  uint32_t memory_planes_ = 1;
  size_t bytes_per_line_[VIDEO_MAX_PLANES] = {};
  bool mjpeg_ = false;
  std::optional<MjpegDecoder> decoder_;
  std::optional<V4L2ExposureControls> controls_;
  std::optional<V4L2MmapBuffers> buffers_;
  bool streaming_ = false;
  int wake_fd_ = -1;
  std::optional<uint32_t> last_sequence_;
  bool warned_clock_ = false;
  mutable std::mutex counters_mutex_;
  StreamCounters counters_;
};

}  // namespace

std::unique_ptr<CameraStream> open_v4l2_stream(const V4L2StreamSettings& settings) {
  return std::make_unique<V4L2Stream>(settings);
}

}  // namespace arpipe
