#include "capture/sinks/http/jpeg_encoder.h"

#include <turbojpeg.h>

#include <fmt/format.h>

#include <memory>
#include <stdexcept>

namespace arpipe {

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
  if (!handle_) throw std::runtime_error(fmt::format("JPEG encoder: {}", tjGetErrorStr2(nullptr)));
}

JpegEncoder::~JpegEncoder() { tjDestroy(handle_); }

std::string JpegEncoder::encode(const Frame& rgb, int quality) {
  if (rgb.format != PixelFormat::RGB24 || rgb.width <= 0 || rgb.height <= 0 ||
      rgb.data.size() < rgb.bytes_per_line * size_t(rgb.height))
    throw std::runtime_error("JPEG encoder: expected a whole RGB24 frame");
  unsigned char* out = nullptr;
  unsigned long size = 0;
  if (tjCompress2(handle_, rgb.data.data(), rgb.width, int(rgb.bytes_per_line), rgb.height, TJPF_RGB, &out, &size,
                  TJSAMP_420, quality, TJFLAG_FASTDCT) != 0) {
    tjFree(out);
    throw std::runtime_error(fmt::format("JPEG encoder: {}", tjGetErrorStr2(handle_)));
  }
  const std::unique_ptr<unsigned char, void (*)(unsigned char*)> owned(out, tjFree);
  return std::string(reinterpret_cast<const char*>(out), size);
}

}  // namespace arpipe
