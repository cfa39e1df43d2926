#include "capture/v4l2/v4l2_device.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>

#include "capture/live/camera_stream.h"

namespace arpipe {

std::string fourcc_text(uint32_t fourcc) {
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i) {
    const char c = char((fourcc >> (8 * i)) & 0xff);
    text[size_t(i)] = (c >= 32 && c < 127) ? c : '?';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();  // "Y16 " -> "Y16"
  return text;
}

std::string describe_device_path(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_symlink(path, ec)) return path;
  const auto target = std::filesystem::canonical(path, ec);
  if (ec) return fmt::format("{} -> {}", path, std::filesystem::read_symlink(path, ec).string());
  return fmt::format("{} -> {}", path, target.string());
}

V4L2Device::V4L2Device(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int err = errno;
    const std::string why = std::strerror(err);
    if (err == ENOENT || err == ENODEV || err == ENXIO)
      throw CameraError(CameraError::Kind::Missing, fmt::format("{}: no such camera now ({})", path_, why));
    if (err == EACCES || err == EPERM)
      throw CameraError(CameraError::Kind::Failed,
                        fmt::format("{}: {} (add the user to the 'video' group)", path_, why));
    throw CameraError(CameraError::Kind::Failed, fmt::format("{}: cannot open: {}", path_, why));
  }
  v4l2_capability cap{};
  if (const int err = ioctl(VIDIOC_QUERYCAP, &cap); err != 0) {
    ::close(fd_);
    fd_ = -1;
    throw CameraError(err == ENODEV ? CameraError::Kind::Missing : CameraError::Kind::Failed,
                      fmt::format("{}: not a V4L2 device (VIDIOC_QUERYCAP: {})", path_, std::strerror(err)));
  }
  driver_ = reinterpret_cast<const char*>(cap.driver);
  card_ = reinterpret_cast<const char*>(cap.card);
  bus_info_ = reinterpret_cast<const char*>(cap.bus_info);
  device_caps_ = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
}

V4L2Device::~V4L2Device() {
  if (fd_ >= 0) ::close(fd_);
}

int V4L2Device::ioctl(unsigned long request, void* arg) const noexcept {
  for (;;) {
    if (::ioctl(fd_, request, arg) == 0) return 0;
    if (errno != EINTR) return errno;
  }
}

bool V4L2Device::can_capture() const {
  return (device_caps_ & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE)) && (device_caps_ & V4L2_CAP_STREAMING);
}

bool V4L2Device::multi_planar() const {
  return !(device_caps_ & V4L2_CAP_VIDEO_CAPTURE) && (device_caps_ & V4L2_CAP_VIDEO_CAPTURE_MPLANE);
}

uint32_t V4L2Device::buffer_type() const {
  return multi_planar() ? V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE : V4L2_BUF_TYPE_VIDEO_CAPTURE;
}

namespace {

std::vector<V4L2Fraction> enumerate_intervals(const V4L2Device& device, uint32_t fourcc, uint32_t width,
                                              uint32_t height, std::string& note) {
  std::vector<V4L2Fraction> intervals;
  for (uint32_t index = 0;; ++index) {
    v4l2_frmivalenum e{};
    e.index = index;
    e.pixel_format = fourcc;
    e.width = width;
    e.height = height;
    if (device.ioctl(VIDIOC_ENUM_FRAMEINTERVALS, &e) != 0) break;
    if (e.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      intervals.push_back({e.discrete.numerator, e.discrete.denominator});
      continue;
    }
    const V4L2Fraction slow{e.stepwise.max.numerator, e.stepwise.max.denominator};
    const V4L2Fraction fast{e.stepwise.min.numerator, e.stepwise.min.denominator};
    note = fmt::format("{} {:.3g} to {:.3g} fps", e.type == V4L2_FRMIVAL_TYPE_CONTINUOUS ? "continuous" : "stepwise",
                       slow.fps(), fast.fps());
    break;
  }
  return intervals;
}

}  // namespace

std::vector<V4L2FormatOffer> V4L2Device::enumerate_formats() const {
  std::vector<V4L2FormatOffer> offers;
  for (uint32_t index = 0;; ++index) {
    v4l2_fmtdesc desc{};
    desc.index = index;
    desc.type = buffer_type();
    if (ioctl(VIDIOC_ENUM_FMT, &desc) != 0) break;
    V4L2FormatOffer offer;
    offer.fourcc = desc.pixelformat;
    offer.compressed = desc.flags & V4L2_FMT_FLAG_COMPRESSED;
    for (uint32_t size_index = 0;; ++size_index) {
      v4l2_frmsizeenum size{};
      size.index = size_index;
      size.pixel_format = desc.pixelformat;
      if (ioctl(VIDIOC_ENUM_FRAMESIZES, &size) != 0) break;
      if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        V4L2FrameSize s{size.discrete.width, size.discrete.height, {}, {}};
        s.intervals = enumerate_intervals(*this, desc.pixelformat, s.width, s.height, s.note);
        offer.sizes.push_back(std::move(s));
        continue;
      }
      // Stepwise or continuous: the two ends stand for the range; the note says what lies between.
      const auto& sw = size.stepwise;
      offer.note = fmt::format("{} {}x{} to {}x{} step {}x{}",
                               size.type == V4L2_FRMSIZE_TYPE_CONTINUOUS ? "continuous" : "stepwise", sw.min_width,
                               sw.min_height, sw.max_width, sw.max_height, sw.step_width, sw.step_height);
      for (const auto& [w, h] : {std::pair{sw.max_width, sw.max_height}, std::pair{sw.min_width, sw.min_height}}) {
        V4L2FrameSize s{w, h, {}, {}};
        s.intervals = enumerate_intervals(*this, desc.pixelformat, w, h, s.note);
        offer.sizes.push_back(std::move(s));
      }
      break;
    }
    offers.push_back(std::move(offer));
  }
  return offers;
}

}  // namespace arpipe
