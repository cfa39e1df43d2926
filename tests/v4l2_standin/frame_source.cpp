#include "frame_source.h"

#include <fmt/format.h>
#include <linux/videodev2.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "core/image/pixel_convert.h"

namespace arpipe::standin {

namespace {

// Format descriptions as the kernel's v4l_fill_fmtdesc words them, in the words Debian 12's
// v4l2-compliance (1.22) checks (kernels since 6.0 say "Y/UV" where it says "Y/CbCr").
const char* description_of(uint32_t fourcc) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: return "YUYV 4:2:2";
    case V4L2_PIX_FMT_MJPEG: return "Motion-JPEG";
    case V4L2_PIX_FMT_RGB24: return "24-bit RGB 8-8-8";
    case V4L2_PIX_FMT_GREY: return "8-bit Greyscale";
    case V4L2_PIX_FMT_NV12: return "Y/CbCr 4:2:0";
    case V4L2_PIX_FMT_UYVY: return "UYVY 4:2:2";
    case V4L2_PIX_FMT_YVYU: return "YVYU 4:2:2";
    case V4L2_PIX_FMT_NV21: return "Y/CrCb 4:2:0";
    case V4L2_PIX_FMT_YUV420: return "Planar YUV 4:2:0";
    case V4L2_PIX_FMT_NV16: return "Y/CbCr 4:2:2";
    case V4L2_PIX_FMT_NV12M: return "Y/CbCr 4:2:0 (N-C)";
    case V4L2_PIX_FMT_NV21M: return "Y/CrCb 4:2:0 (N-C)";
    case V4L2_PIX_FMT_YUV420M: return "Planar YUV 4:2:0 (N-C)";
    case V4L2_PIX_FMT_NV16M: return "Y/CbCr 4:2:2 (N-C)";
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
    default: break;
  }
  return PixelFormat::YUYV;  // not reached: the caller handles Native, Mjpg and the derived ones
}

struct DerivedName {
  OfferedFormatName name;
  DerivedLayout layout;
  uint32_t fourcc;
  bool split;
};
// The formats made by reordering YUYV or NV12 bytes (NV12M is NV12's bytes split, below).
constexpr DerivedName kDerived[] = {
    {OfferedFormatName::Uyvy, DerivedLayout::Uyvy, V4L2_PIX_FMT_UYVY, false},
    {OfferedFormatName::Yvyu, DerivedLayout::Yvyu, V4L2_PIX_FMT_YVYU, false},
    {OfferedFormatName::Nv16, DerivedLayout::Nv16, V4L2_PIX_FMT_NV16, false},
    {OfferedFormatName::Nv21, DerivedLayout::Nv21, V4L2_PIX_FMT_NV21, false},
    {OfferedFormatName::Yu12, DerivedLayout::Yu12, V4L2_PIX_FMT_YUV420, false},
    {OfferedFormatName::Nv16m, DerivedLayout::Nv16, V4L2_PIX_FMT_NV16M, true},
    {OfferedFormatName::Nv21m, DerivedLayout::Nv21, V4L2_PIX_FMT_NV21M, true},
    {OfferedFormatName::Yuv420m, DerivedLayout::Yu12, V4L2_PIX_FMT_YUV420M, true}};

// The planes a format is cut into when served multi-planar: one (the whole image) unless split.
void set_planes(OfferedFormat& f, bool split, uint32_t width, uint32_t height) {
  f.num_planes = 1;
  f.plane_bytes_per_line[0] = f.bytes_per_line;
  f.plane_size[0] = f.size_image;
  if (!split) return;
  const uint32_t y = f.bytes_per_line * height;
  f.plane_size[0] = y;
  switch (f.fourcc) {
    case V4L2_PIX_FMT_NV12M:
    case V4L2_PIX_FMT_NV21M:
    case V4L2_PIX_FMT_NV16M:
      f.num_planes = 2;
      f.plane_bytes_per_line[1] = f.bytes_per_line;
      f.plane_size[1] = f.size_image - y;
      break;
    case V4L2_PIX_FMT_YUV420M:
      f.num_planes = 3;
      f.plane_bytes_per_line[1] = f.plane_bytes_per_line[2] = width / 2;
      f.plane_size[1] = f.plane_size[2] = (f.size_image - y) / 2;
      break;
  }
}

// A layout's size rules (4:2:2 pairs columns; 4:2:0 also rows), or nullopt when it fits.
std::optional<std::string> check_derived_size(DerivedLayout layout, int width, int height) {
  if (width < 2 || height < 2) return "it needs at least 2x2 pixels";
  if (width % 2 != 0) return "it needs an even width";
  if (!derived_from_yuyv(layout) && height % 2 != 0) return "it needs an even height";
  return std::nullopt;
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
    } else if (format == OfferedFormatName::Nv12m) {
      if (const auto bad = check_image_size(PixelFormat::NV12, info.width, info.height))
        throw StandinConfigError(fmt::format("{}: format {} cannot carry the recording's {}x{} frames: {}",
                                             config.formats_place, name, info.width, info.height, *bad));
      f = make_format(PixelFormat::NV12, info.pixel_format == PixelFormat::NV12, info);
      f.fourcc = V4L2_PIX_FMT_NV12M;
      f.description = description_of(f.fourcc);
    } else if (const auto d = std::find_if(std::begin(kDerived), std::end(kDerived),
                                           [&](const DerivedName& n) { return n.name == format; });
               d != std::end(kDerived)) {
      if (const auto bad = check_derived_size(d->layout, info.width, info.height))
        throw StandinConfigError(fmt::format("{}: format {} cannot carry the recording's {}x{} frames: {}",
                                             config.formats_place, name, info.width, info.height, *bad));
      f = make_format(std::nullopt, false, info);
      f.derived = d->layout;
      f.fourcc = d->fourcc;
      f.description = description_of(f.fourcc);
      f.quantization = V4L2_QUANTIZATION_LIM_RANGE;
      f.bytes_per_line = uint32_t(derived_from_yuyv(d->layout) && d->layout != DerivedLayout::Nv16 ? info.width * 2 : info.width);
      f.size_image = uint32_t(derived_bytes(d->layout, info.width, info.height));
    } else {
      const PixelFormat raw = raw_format(format);
      if (const auto bad = check_image_size(raw, info.width, info.height))
        throw StandinConfigError(fmt::format("{}: format {} cannot carry the recording's {}x{} frames: {}",
                                             config.formats_place, name, info.width, info.height, *bad));
      f = make_format(raw, raw == info.pixel_format, info);
    }
    const bool split = format == OfferedFormatName::Nv12m || multi_planar_only(format);
    set_planes(f, split, uint32_t(info.width), uint32_t(info.height));
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
  if (format.derived) {
    // The YUYV or NV12 image this device would serve (the recording's own bytes when it is in that
    // format, else arpipe's conversion), reordered.
    const PixelFormat basis = derived_from_yuyv(*format.derived) ? PixelFormat::YUYV : PixelFormat::NV12;
    const size_t n = derived_bytes(*format.derived, frame_.width, frame_.height);
    if (n > capacity) return 0;
    if (frame_.format == basis) {
      derive_layout(*format.derived, frame_.data.data(), frame_.bytes_per_line, frame_.width, frame_.height, dst);
    } else {
      to_rgb24(frame_, rgb_);
      const Frame converted = from_rgb24(rgb_.data(), frame_.width, frame_.height, basis);
      derive_layout(*format.derived, converted.data.data(), converted.bytes_per_line, frame_.width, frame_.height, dst);
    }
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
