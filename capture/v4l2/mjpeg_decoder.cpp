#include "capture/v4l2/mjpeg_decoder.h"

#include <turbojpeg.h>

#include <stdexcept>

#include <fmt/format.h>

namespace arpipe {

MjpegDecoder::MjpegDecoder() : handle_(tjInitDecompress()) {
  if (handle_ == nullptr) throw std::runtime_error(fmt::format("libturbojpeg: {}", tjGetErrorStr2(nullptr)));
}

MjpegDecoder::~MjpegDecoder() {
  if (handle_) tjDestroy(handle_);
}

bool MjpegDecoder::decode(const uint8_t* jpeg, size_t size, int width, int height, Frame& out, std::string& why) {
  int jpeg_width = 0, jpeg_height = 0, subsampling = 0, colorspace = 0;
  if (size == 0 || tjDecompressHeader3(handle_, jpeg, static_cast<unsigned long>(size), &jpeg_width, &jpeg_height,
                                       &subsampling, &colorspace) != 0) {
    why = fmt::format("MJPEG frame of {} bytes has no readable JPEG header: {}", size, tjGetErrorStr2(handle_));
    return false;
  }
  if (jpeg_width != width || jpeg_height != height) {
    why = fmt::format("MJPEG frame is {}x{}, the stream {}x{}", jpeg_width, jpeg_height, width, height);
    return false;
  }
  out.reshape(PixelFormat::RGB24, width, height);  // a recycled frame's memory is reused
  // TJFLAG_STOPONWARNING: a truncated frame (a USB packet lost) is an error, not grey rows.
  if (tjDecompress2(handle_, jpeg, static_cast<unsigned long>(size), out.data.data(), width,
                    static_cast<int>(out.bytes_per_line), height, TJPF_RGB, TJFLAG_STOPONWARNING) != 0) {
    why = fmt::format("MJPEG frame of {} bytes does not decode: {}", size, tjGetErrorStr2(handle_));
    return false;
  }
  return true;
}

}  // namespace arpipe
