// JPEG encode and decode of simulated frames through libjpeg-turbo's TurboJPEG API.
#include "capture/sim/jpeg_round_trip.h"

#include <fmt/format.h>
#include <turbojpeg.h>

#include <memory>
#include <stdexcept>

namespace arpipe::sim {

namespace {

using Handle = std::unique_ptr<void, int (*)(tjhandle)>;

void check_arguments(int width, int height, size_t bytes_per_line, int channels, int quality) {
  if (channels != 1 && channels != 3)
    throw std::invalid_argument(fmt::format("JPEG round trip: 1 or 3 channels, got {}", channels));
  if (width <= 0 || height <= 0 || bytes_per_line < size_t(width) * size_t(channels))
    throw std::invalid_argument(fmt::format("JPEG round trip: a {}x{} image with {} bytes a line", width, height,
                                            bytes_per_line));
  if (quality < 1 || quality > 100)
    throw std::invalid_argument(fmt::format("JPEG round trip: quality must be in 1..100, got {}", quality));
}

}  // namespace

std::string jpeg_encode(const uint8_t* pixels, int width, int height, size_t bytes_per_line, int channels, int quality) {
  check_arguments(width, height, bytes_per_line, channels, quality);
  const Handle handle(tjInitCompress(), tjDestroy);
  if (!handle) throw std::runtime_error(fmt::format("JPEG encoder: {}", tjGetErrorStr2(nullptr)));
  unsigned char* out = nullptr;
  unsigned long size = 0;
  if (tjCompress2(handle.get(), pixels, width, int(bytes_per_line), height, channels == 3 ? TJPF_RGB : TJPF_GRAY,
                  &out, &size, channels == 3 ? TJSAMP_420 : TJSAMP_GRAY, quality, TJFLAG_ACCURATEDCT) != 0) {
    tjFree(out);
    throw std::runtime_error(fmt::format("JPEG encoder: {}", tjGetErrorStr2(handle.get())));
  }
  const std::unique_ptr<unsigned char, void (*)(unsigned char*)> owned(out, tjFree);
  return std::string(reinterpret_cast<const char*>(out), size);
}

void jpeg_round_trip(uint8_t* pixels, int width, int height, size_t bytes_per_line, int channels, int quality) {
  const std::string jpeg = jpeg_encode(pixels, width, height, bytes_per_line, channels, quality);
  const Handle handle(tjInitDecompress(), tjDestroy);
  if (!handle) throw std::runtime_error(fmt::format("JPEG decoder: {}", tjGetErrorStr2(nullptr)));
  if (tjDecompress2(handle.get(), reinterpret_cast<const unsigned char*>(jpeg.data()), jpeg.size(), pixels, width,
                    int(bytes_per_line), height, channels == 3 ? TJPF_RGB : TJPF_GRAY, TJFLAG_ACCURATEDCT) != 0)
    throw std::runtime_error(fmt::format("JPEG decoder: {}", tjGetErrorStr2(handle.get())));
}

}  // namespace arpipe::sim
