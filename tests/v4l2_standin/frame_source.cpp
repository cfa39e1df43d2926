#include "frame_source.h"

#include <fmt/format.h>
#include <linux/videodev2.h>
#include <turbojpeg.h>

#include <cstdio>
#include <cstring>

#include "core/image/pixel_convert.h"

namespace arpipe::standin {

namespace {

// Format descriptions as the kernel's v4l_fill_fmtdesc words them.
const char* description_of(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: return "YUYV 4:2:2";
    case V4L2_PIX_FMT_MJPEG: return "Motion-JPEG";
    case V4L2_PIX_FMT_RGB24: return "24-bit RGB 8-8-8";
    case V4L2_PIX_FMT_GREY: return "8-bit Greyscale";
    case V4L2_PIX_FMT_NV12: return "Y/UV 4:2:0";
  }
  return "?";
}

OfferedFormat make_format(std::optional<PixelFormat> raw, bool native, const RecordingInfo& info) {
  OfferedFormat f;
  f.raw = raw;
  f.native = native;
  f.fourcc = raw ? pixel_format_fourcc(*raw) : V4L2_PIX_FMT_MJPEG;
  f.description = description_of(f.fourcc);
  f.colorspace = V4L2_COLORSPACE_SRGB;
  f.xfer_func = V4L2_XFER_FUNC_SRGB;
  f.ycbcr_enc = V4L2_YCBCR_ENC_601;
  const bool yuv = raw && (*raw == PixelFormat::YUYV || *raw == PixelFormat::NV12);
  f.quantization = yuv ? V4L2_QUANTIZATION_LIM_RANGE : V4L2_QUANTIZATION_FULL_RANGE;
  if (!raw) {
    f.bytes_per_line = 0;
    f.size_image = uint32_t(tjBufSize(info.width, info.height, TJSAMP_422));
  } else {
    const size_t stride = native ? info.bytes_per_line : min_bytes_per_line(*raw, info.width);
    f.bytes_per_line = uint32_t(stride);
    f.size_image = uint32_t(image_bytes(*raw, info.width, info.height, stride));
  }
  return f;
}

// The pixel format a converted format offers (not Native or Mjpg).
PixelFormat raw_format(OfferedFormatName format) {
  switch (format) {
    case OfferedFormatName::Yuyv: return PixelFormat::YUYV;
    case OfferedFormatName::Rgb24: return PixelFormat::RGB24;
    case OfferedFormatName::Grey: return PixelFormat::GREY;
    case OfferedFormatName::Nv12: return PixelFormat::NV12;
    case OfferedFormatName::Native:
    case OfferedFormatName::Mjpg: break;
  }
  return PixelFormat::YUYV;  // not reached: the caller handles Native and Mjpg
}

}  // namespace

FrameSource::FrameSource(const DeviceConfig& config) : config_(config) {
  try {
    reader_ = std::make_unique<RecordingReader>(config.recording);
  } catch (const std::exception& e) {
    throw StandinConfigError(fmt::format("{}: cannot read recording \"{}\": {}", config.place, config.recording.string(), e.what()));
  }
  const RecordingInfo& info = reader_->info();
  if (reader_->frame_count() == 0)
    throw StandinConfigError(fmt::format("{}: recording \"{}\" has no frames", config.place, config.recording.string()));
  for (const OfferedFormatName format : config.formats) {
    const std::string_view name = choice_name<OfferedFormatName>(kOfferedFormatNames, format);
    OfferedFormat f;
    if (format == OfferedFormatName::Native) {
      f = make_format(info.pixel_format, true, info);
    } else if (format == OfferedFormatName::Mjpg) {
      f = make_format(std::nullopt, false, info);
    } else {
      const PixelFormat raw = raw_format(format);
      if (const auto bad = check_image_size(raw, info.width, info.height))
        throw StandinConfigError(fmt::format("{}: format {} cannot carry the recording's {}x{} frames: {}",
                                             config.formats_place, name, info.width, info.height, *bad));
      f = make_format(raw, raw == info.pixel_format, info);
    }
    for (const OfferedFormat& other : formats_)
      if (other.fourcc == f.fourcc)
        throw StandinConfigError(fmt::format("{}: 'formats' offers {} twice (\"native\" is the recording's {})",
                                             config.formats_place, name, pixel_format_name(info.pixel_format)));
    formats_.push_back(f);
  }
  for (const Fault& fault : config.faults)
    if (fault.frame >= reader_->frame_count())
      throw StandinConfigError(fmt::format("{}: fault frame {} is past the recording's last frame {}", fault.place,
                                           fault.frame, reader_->frame_count() - 1));
  const size_t n = reader_->frame_count();
  interval_ns_ = reader_->metadata(0).frame_duration_ns;
  if (interval_ns_ <= 0 && n > 1)
    interval_ns_ = (reader_->metadata(n - 1).exposure_start_ns - reader_->metadata(0).exposure_start_ns) / int64_t(n - 1);
  if (interval_ns_ <= 0)
    throw StandinConfigError(fmt::format("{}: recording \"{}\" has no frame interval (frame_duration_ns of frame 0 is 0 "
                                         "and there is no second frame)", config.place, config.recording.string()));
  jpeg_ = tjInitCompress();
}

FrameSource::~FrameSource() {
  if (jpeg_ != nullptr) tjDestroy(jpeg_);
}

size_t FrameSource::frame_count() const { return reader_->frame_count(); }
int FrameSource::width() const { return reader_->info().width; }
int FrameSource::height() const { return reader_->info().height; }
const FrameMetadata& FrameSource::metadata(size_t index) const { return reader_->metadata(index); }

int64_t FrameSource::exposure_end_ns(size_t index) const {
  const FrameMetadata& m = reader_->metadata(index);
  return m.exposure_start_ns + m.exposure_ns + m.readout_ns;
}

size_t FrameSource::render(size_t index, const OfferedFormat& format, uint8_t* dst, size_t capacity) {
  try {
    reader_->read(index, frame_);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "arpipe-v4l2-standin: %s\n", e.what());
    return 0;
  }
  if (format.native) {
    const size_t n = std::min(frame_.data.size(), capacity);
    std::memcpy(dst, frame_.data.data(), n);
    return n;
  }
  to_rgb24(frame_, rgb_);
  if (format.raw) {
    const Frame converted = from_rgb24(rgb_.data(), frame_.width, frame_.height, *format.raw);
    const size_t n = std::min(converted.data.size(), capacity);
    std::memcpy(dst, converted.data.data(), n);
    return n;
  }
  unsigned char* out = dst;
  unsigned long size = capacity;
  // 4:2:2 like UVC webcams' MJPEG; NOREALLOC: dst holds tjBufSize bytes (size_image).
  if (tjCompress2(jpeg_, rgb_.data(), frame_.width, 0, frame_.height, TJPF_RGB, &out, &size, TJSAMP_422,
                  config_.jpeg_quality, TJFLAG_NOREALLOC) != 0) {
    std::fprintf(stderr, "arpipe-v4l2-standin: %s: JPEG compression failed: %s\n", config_.path.c_str(), tjGetErrorStr2(jpeg_));
    return 0;
  }
  return size_t(size);
}

}  // namespace arpipe::standin
