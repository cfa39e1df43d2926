// An open V4L2 device node: the fd, ioctls that retry on EINTR, and what the driver says it is
// and offers (capabilities, formats with their sizes and frame intervals).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace arpipe {

struct V4L2Fraction {
  uint32_t numerator = 0;
  uint32_t denominator = 0;
  double fps() const { return numerator ? double(denominator) / numerator : 0; }
  int64_t ns() const { return denominator ? int64_t(numerator) * 1'000'000'000 / denominator : 0; }
};

struct V4L2FrameSize {
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<V4L2Fraction> intervals;  // discrete intervals as listed; empty: not enumerable
  std::string note;                     // stepwise/continuous interval ranges, in words
};

struct V4L2FormatOffer {
  uint32_t fourcc = 0;
  bool compressed = false;
  std::vector<V4L2FrameSize> sizes;  // discrete sizes, or the two ends of a stepwise range
  std::string note;                  // "stepwise 160x120 to 1920x1080 step 8x8", in words
};

// "YUYV", "MJPG", ...: the four characters of a V4L2 FourCC (non-printable bytes as '?').
std::string fourcc_text(uint32_t fourcc);

class V4L2Device {
 public:
  // Opens read-write, non-blocking, close-on-exec. Throws CameraError: Missing when the node is
  // not there (ENOENT, ENODEV, ENXIO), Failed otherwise (EACCES says to join the video group).
  explicit V4L2Device(std::string path);
  ~V4L2Device();
  V4L2Device(const V4L2Device&) = delete;
  V4L2Device& operator=(const V4L2Device&) = delete;

  const std::string& path() const { return path_; }
  int fd() const { return fd_; }
  // ioctl, retried on EINTR; returns 0 or the errno.
  int ioctl(unsigned long request, void* arg) const noexcept;

  std::string driver() const { return driver_; }
  std::string card() const { return card_; }
  std::string bus_info() const { return bus_info_; }
  uint32_t device_caps() const { return device_caps_; }
  bool can_capture() const;  // video capture (single- or multi-planar) with streaming I/O
  // V4L2_BUF_TYPE_VIDEO_CAPTURE, or VIDEO_CAPTURE_MPLANE for a device that only captures
  // multi-planar (many MIPI receivers and ISPs: Rockchip, i.MX); every format, buffer and stream
  // ioctl then takes that type.
  uint32_t buffer_type() const;
  bool multi_planar() const;

  // Every format of buffer_type() with its sizes and their frame intervals (ENUM_FMT, ENUM_FRAMESIZES,
  // ENUM_FRAMEINTERVALS). Non-throwing: a driver that lists nothing gives an empty list.
  std::vector<V4L2FormatOffer> enumerate_formats() const;

 private:
  std::string path_;
  int fd_ = -1;
  std::string driver_, card_, bus_info_;
  uint32_t device_caps_ = 0;
};

// "/dev/v4l/by-id/usb-...-video-index0 -> /dev/video0" when path is a link, else path.
std::string describe_device_path(const std::string& path);

}  // namespace arpipe
