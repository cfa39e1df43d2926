// A served device's frames: the recording behind it, its schedule (exposure ends, interval) and its
// pixels converted to each offered V4L2 pixel format (native bytes, YUYV/RGB24/GREY/NV12, MJPG).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "standin_config.h"
#include "yuv_layouts.h"

namespace arpipe::standin {

inline constexpr uint32_t kMaxPlanes = 3;

struct OfferedFormat {
  uint32_t fourcc = 0;
  std::optional<PixelFormat> raw;  // nullopt: MJPG or a derived layout
  std::optional<DerivedLayout> derived;  // UYVY, YVYU, NV16, NV21, YU12 and their split twins
  bool native = false;             // the recording's own bytes, stride included
  uint32_t bytes_per_line = 0;     // 0 for MJPG
  uint32_t size_image = 0;         // MJPG: the largest JPEG (tjBufSize)
  // Multi-planar: the image cut into planes, in order (split formats: 2 or 3; the rest: 1 = the whole image).
  uint32_t num_planes = 1;
  uint32_t plane_bytes_per_line[kMaxPlanes] = {};
  uint32_t plane_size[kMaxPlanes] = {};
  uint32_t colorspace = 0, ycbcr_enc = 0, quantization = 0, xfer_func = 0;
  const char* description = "";
};

class FrameSource {
 public:
  // Opens the recording and resolves the offered formats. Throws StandinConfigError naming the
  // config's place (bad format names, sizes a format cannot take, fault frames past the end, an
  // unreadable recording).
  explicit FrameSource(const DeviceConfig& config);
  ~FrameSource();

  size_t frame_count() const;
  int width() const;
  int height() const;
  const FrameMetadata& metadata(size_t index) const;
  // The recording's frame interval: frame 0's frame_duration_ns, else the mean spacing of exposure starts.
  int64_t interval_ns() const { return interval_ns_; }
  // Recorded end of exposure of the last row (start + exposure + readout): when the frame falls due.
  int64_t exposure_end_ns(size_t index) const;
  const std::vector<OfferedFormat>& formats() const { return formats_; }

  // Writes frame `index` in `format` into dst (capacity bytes, at least format.size_image) and
  // returns the bytes used. Never throws: an unreadable frame gives 0 (and a message on stderr).
  size_t render(size_t index, const OfferedFormat& format, uint8_t* dst, size_t capacity);

 private:
  const DeviceConfig& config_;
  std::unique_ptr<RecordingReader> reader_;
  std::vector<OfferedFormat> formats_;
  int64_t interval_ns_ = 0;
  void* jpeg_ = nullptr;  // tjhandle
  Frame frame_;
  std::vector<uint8_t> rgb_;
};

}  // namespace arpipe::standin
