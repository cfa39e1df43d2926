#include "capture/sinks/v4l2/v4l2_output_sink.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <numeric>
#include <stdexcept>

#include "core/image/pixel_convert.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

constexpr const char* kV4l2SinkKey = "sinks.v4l2.device";
constexpr int64_t kV4l2SinkRetryNs = 1'000'000'000;
constexpr uint32_t kV4l2SinkMaxImageBytes = 1u << 30;  // 16384 x 16384 x 3 < 1 GiB: any larger answer is nonsense

int v4l2_sink_ioctl(int fd, unsigned long request, void* arg) {
  int r;
  do r = ::ioctl(fd, request, arg);
  while (r < 0 && errno == EINTR);
  return r;
}

std::string v4l2_sink_fourcc_name(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = char((fourcc >> (8 * i)) & 0xff);
    s += (c >= ' ' && c <= '~') ? c : '?';
  }
  return s;
}

std::string v4l2_sink_errno(const char* call) { return fmt::format("{}: {}", call, std::strerror(errno)); }

}  // namespace

int64_t V4l2OutputSink::dequeue_wait_ns(int64_t frame_duration_ns) {
  if (frame_duration_ns <= 0) return 100'000'000;
  return std::clamp<int64_t>(frame_duration_ns > INT64_MAX / 2 ? INT64_MAX : 2 * frame_duration_ns, 50'000'000,
                             1'000'000'000);
}

V4l2OutputSink::V4l2OutputSink(const V4l2SinkConfig& config)
    : device_(config.device),
      format_(config.format),
      fourcc_(config.format == V4l2OutputFormat::Rgb24 ? V4L2_PIX_FMT_RGB24 : V4L2_PIX_FMT_YUYV),
      outage_(fmt::format("{} = \"{}\"", kV4l2SinkKey, config.device.string()),
              "its readers keep the last frame written") {
  if (const std::string why = open_device(); !why.empty())
    throw std::runtime_error(fmt::format("{} = \"{}\": {}", kV4l2SinkKey, device_.string(), why));
  // Where the driver lists what it takes without the configured format, say so now; the first
  // frame's VIDIOC_S_FMT decides. Not a refusal: v4l2loopback lists only the format being written
  // while another writer streams, as the sink a reload replaces still does when this one is made.
  std::vector<uint32_t> offered;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    if (v4l2_sink_ioctl(fd_, VIDIOC_ENUM_FMT, &d) != 0) break;
    offered.push_back(d.pixelformat);
  }
  if (!offered.empty() && std::find(offered.begin(), offered.end(), fourcc_) == offered.end()) {
    std::string names;
    for (const uint32_t f : offered) names += (names.empty() ? "" : ", ") + v4l2_sink_fourcc_name(f);
    log::warn("{} = \"{}\": the device lists {}, not {} (sinks.v4l2.format); the first frame will tell", kV4l2SinkKey,
              device_.string(), names, v4l2_sink_fourcc_name(fourcc_));
  }
}

V4l2OutputSink::~V4l2OutputSink() {
  close_device();
  outage_.report_at_end();
}

std::string V4l2OutputSink::describe() const {
  return fmt::format("v4l2:{} ({})", device_.string(), choice_name(kV4l2OutputFormatNames, format_));
}

std::string V4l2OutputSink::open_device() {
  // Non-blocking: a DQBUF never waits, poll() does, with a bound.
  fd_ = ::open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0)
    return fmt::format("cannot open it: {} (for v4l2loopback: modprobe v4l2loopback video_nr=N exclusive_caps=1)",
                       std::strerror(errno));
  v4l2_capability cap{};
  if (v4l2_sink_ioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
    const std::string why = fmt::format("not a V4L2 device ({})", v4l2_sink_errno("VIDIOC_QUERYCAP"));
    close_device();
    return why;
  }
  const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  if ((caps & V4L2_CAP_VIDEO_OUTPUT) == 0 || (caps & V4L2_CAP_STREAMING) == 0) {
    const std::string why = fmt::format(
        "\"{}\" is not a streaming video output device (capabilities 0x{:08x}: expected VIDEO_OUTPUT and STREAMING); "
        "is it the loopback's own node?",
        std::string(reinterpret_cast<const char*>(cap.card), strnlen(reinterpret_cast<const char*>(cap.card), sizeof cap.card)),
        caps);
    close_device();
    return why;
  }
  return "";
}

void V4l2OutputSink::close_device() noexcept {
  if (fd_ >= 0 && streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    v4l2_sink_ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  for (const Mapping& m : mappings_) ::munmap(m.data, m.length);
  mappings_.clear();
  free_.clear();
  streaming_ = false;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

std::string V4l2OutputSink::start_stream(const Frame& frame) {
  // 4:2:2 pairs columns: an odd last column is left out rather than the frame (as the Y4M sink does).
  const int width = format_ == V4l2OutputFormat::Yuyv ? frame.width & ~1 : frame.width;
  const int height = frame.height;
  if (width < 1 || height < 1) return fmt::format("a {}x{} frame cannot be written", frame.width, frame.height);
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  f.fmt.pix.width = uint32_t(width);
  f.fmt.pix.height = uint32_t(height);
  f.fmt.pix.pixelformat = fourcc_;
  f.fmt.pix.field = V4L2_FIELD_NONE;
  f.fmt.pix.colorspace = V4L2_COLORSPACE_SRGB;
  if (v4l2_sink_ioctl(fd_, VIDIOC_S_FMT, &f) != 0) return v4l2_sink_errno("VIDIOC_S_FMT");
  // A driver adjusts what it cannot do; the stream is this size and format or nothing.
  if (f.fmt.pix.pixelformat != fourcc_ || f.fmt.pix.width != uint32_t(width) || f.fmt.pix.height != uint32_t(height))
    return fmt::format("asked for {} {}x{}, the driver answered {} {}x{}", v4l2_sink_fourcc_name(fourcc_), width, height,
                       v4l2_sink_fourcc_name(f.fmt.pix.pixelformat), f.fmt.pix.width, f.fmt.pix.height);
  const uint32_t min_line = uint32_t(width) * (format_ == V4l2OutputFormat::Yuyv ? 2 : 3);
  const uint32_t line = f.fmt.pix.bytesperline == 0 ? min_line : f.fmt.pix.bytesperline;
  if (line < min_line || line > kV4l2SinkMaxImageBytes / uint32_t(height) || f.fmt.pix.sizeimage < line * uint32_t(height) ||
      f.fmt.pix.sizeimage > kV4l2SinkMaxImageBytes)
    return fmt::format("the driver answered {} bytes a line and {} bytes an image for {} {}x{}", f.fmt.pix.bytesperline,
                       f.fmt.pix.sizeimage, v4l2_sink_fourcc_name(fourcc_), width, height);
  width_ = width;
  height_ = height;
  bytes_per_line_ = line;
  size_image_ = f.fmt.pix.sizeimage;

  // The frame rate readers are told (v4l2loopback passes it on); a driver that keeps its own is fine.
  if (frame.meta.frame_duration_ns > 0) {
    v4l2_streamparm p{};
    p.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    int64_t num = frame.meta.frame_duration_ns, den = 1'000'000'000;
    const int64_t g = std::gcd(num, den);
    num /= g;
    den /= g;
    if (num <= UINT32_MAX && den <= UINT32_MAX) {
      p.parm.output.timeperframe = {uint32_t(num), uint32_t(den)};
      v4l2_sink_ioctl(fd_, VIDIOC_S_PARM, &p);
    }
  }

  v4l2_requestbuffers r{};
  r.count = kBuffers;
  r.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  r.memory = V4L2_MEMORY_MMAP;
  if (v4l2_sink_ioctl(fd_, VIDIOC_REQBUFS, &r) != 0) return v4l2_sink_errno("VIDIOC_REQBUFS");
  if (r.count < 1 || r.count > 64) return fmt::format("VIDIOC_REQBUFS: the driver gave {} buffers", r.count);
  for (uint32_t i = 0; i < r.count; ++i) {
    v4l2_buffer b{};
    b.index = i;
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    if (v4l2_sink_ioctl(fd_, VIDIOC_QUERYBUF, &b) != 0) return v4l2_sink_errno("VIDIOC_QUERYBUF");
    if (b.length < size_image_)
      return fmt::format("VIDIOC_QUERYBUF: buffer {} holds {} bytes, an image {}", i, b.length, size_image_);
    void* p = ::mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, off_t(b.m.offset));
    if (p == MAP_FAILED) return v4l2_sink_errno("mmap");
    mappings_.push_back({p, b.length});
    free_.push_back(i);
  }
  int type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  if (v4l2_sink_ioctl(fd_, VIDIOC_STREAMON, &type) != 0) return v4l2_sink_errno("VIDIOC_STREAMON");
  streaming_ = true;
  return "";
}

int V4l2OutputSink::take_buffer(int64_t wait_ns, std::string& why) {
  const int64_t deadline = monotonic_now_ns() + wait_ns;
  for (;;) {
    // Everything the device has finished with comes back first.
    for (;;) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
      b.memory = V4L2_MEMORY_MMAP;
      if (v4l2_sink_ioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
        if (errno == EAGAIN) break;
        why = v4l2_sink_errno("VIDIOC_DQBUF");
        return -1;
      }
      if (b.index >= mappings_.size() || std::find(free_.begin(), free_.end(), b.index) != free_.end()) {
        why = fmt::format("VIDIOC_DQBUF: the driver gave back buffer {}, which the sink did not queue", b.index);
        return -1;
      }
      free_.push_back(b.index);
    }
    if (!free_.empty()) {
      const uint32_t index = free_.front();
      free_.erase(free_.begin());
      return int(index);
    }
    const int64_t left = deadline - monotonic_now_ns();
    if (left <= 0) return -1;  // none came back in time: the frame is dropped
    pollfd p{fd_, POLLOUT, 0};
    const int n = ::poll(&p, 1, int((left + 999'999) / 1'000'000));
    if (n < 0 && errno != EINTR) {
      why = v4l2_sink_errno("poll");
      return -1;
    }
    if (n > 0 && (p.revents & (POLLERR | POLLHUP | POLLNVAL)) && !(p.revents & POLLOUT)) {
      why = fmt::format("poll: the device reports an error (revents 0x{:x})", unsigned(p.revents));
      return -1;
    }
  }
}

void V4l2OutputSink::fill(const Frame& frame, uint8_t* dst) const {
  if (format_ == V4l2OutputFormat::Yuyv) {
    rgb24_to_yuyv(frame.data.data(), frame.bytes_per_line, width_, height_, dst, bytes_per_line_);
    return;
  }
  const size_t row = size_t(width_) * 3;
  for (int y = 0; y < height_; ++y) {
    uint8_t* out = dst + size_t(y) * bytes_per_line_;
    std::memcpy(out, frame.data.data() + size_t(y) * frame.bytes_per_line, row);
    std::memset(out + row, 0, bytes_per_line_ - row);
  }
}

void V4l2OutputSink::failed(uint64_t index, const std::string& why) noexcept {
  ++failures_;
  outage_.failed(index, why);
}

void V4l2OutputSink::consume(const FrameContext& ctx) noexcept {
  const Frame& frame = ctx.output;
  if (frame.empty()) return;
  try {
    if (frame.format != PixelFormat::RGB24 || frame.width < 1 || frame.height < 1 ||
        frame.bytes_per_line < size_t(frame.width) * 3 ||
        frame.data.size() < frame.bytes_per_line * size_t(frame.height - 1) + size_t(frame.width) * 3) {
      failed(ctx.input_index, fmt::format("the composite is not a whole RGB24 {}x{} image", frame.width, frame.height));
      return;
    }
    const int64_t now = monotonic_now_ns();
    if (fd_ < 0 || !streaming_) {
      if (now < retry_at_ns_) {
        failed(ctx.input_index, "the device failed; it is opened again once a second");
        return;
      }
      std::string why = fd_ < 0 ? open_device() : "";
      if (why.empty()) why = start_stream(frame);
      if (!why.empty()) {
        close_device();
        retry_at_ns_ = now + kV4l2SinkRetryNs;
        failed(ctx.input_index, why);
        return;
      }
    }
    const int width = format_ == V4l2OutputFormat::Yuyv ? frame.width & ~1 : frame.width;
    if (width != width_ || frame.height != height_) {
      failed(ctx.input_index, fmt::format("the frame is {}x{}, the stream {}x{} (a device keeps its size while it "
                                          "streams)", frame.width, frame.height, width_, height_));
      return;
    }
    std::string why;
    const int index = take_buffer(dequeue_wait_ns(frame.meta.frame_duration_ns), why);
    if (index < 0) {
      if (why.empty()) {
        ++frames_dropped_;
        outage_.failed(ctx.input_index, fmt::format("no buffer came back from the device within {} ms (a reader that "
                                                    "does not keep up?); the frame is dropped",
                                                    dequeue_wait_ns(frame.meta.frame_duration_ns) / 1'000'000));
      } else {
        close_device();
        retry_at_ns_ = now + kV4l2SinkRetryNs;
        failed(ctx.input_index, why);
      }
      return;
    }
    fill(frame, static_cast<uint8_t*>(mappings_[size_t(index)].data));
    v4l2_buffer b{};
    b.index = uint32_t(index);
    b.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
    b.memory = V4L2_MEMORY_MMAP;
    b.bytesused = size_image_;
    b.field = V4L2_FIELD_NONE;
    b.flags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
    // The exposure start, CLOCK_MONOTONIC, as a timeval (whole microseconds, rounded down).
    const int64_t t = frame.meta.exposure_start_ns;
    const int64_t us = t >= 0 ? t / 1000 : -((-t + 999) / 1000);
    b.timestamp.tv_sec = us >= 0 ? us / 1'000'000 : -((-us + 999'999) / 1'000'000);
    b.timestamp.tv_usec = us - int64_t(b.timestamp.tv_sec) * 1'000'000;
    if (v4l2_sink_ioctl(fd_, VIDIOC_QBUF, &b) != 0) {
      why = v4l2_sink_errno("VIDIOC_QBUF");
      close_device();
      retry_at_ns_ = now + kV4l2SinkRetryNs;
      failed(ctx.input_index, why);
      return;
    }
    ++frames_written_;
    outage_.succeeded(ctx.input_index);
  } catch (const std::exception& e) {  // memory for a message
    failed(ctx.input_index, e.what());
  }
}

}  // namespace arpipe
