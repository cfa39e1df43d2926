// Decodes a UVC camera's Motion-JPEG frames to RGB24 with libjpeg-turbo (TurboJPEG API).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/frame.h"

namespace arpipe {

class MjpegDecoder {
 public:
  MjpegDecoder();
  ~MjpegDecoder();
  MjpegDecoder(const MjpegDecoder&) = delete;
  MjpegDecoder& operator=(const MjpegDecoder&) = delete;

  // Decodes into `out` (RGB24, width x height). False with the reason in `why` for a corrupt or
  // truncated JPEG or one of another size; never throws for bad data.
  bool decode(const uint8_t* jpeg, size_t size, int width, int height, Frame& out, std::string& why);

 private:
  void* handle_ = nullptr;  // tjhandle
};

}  // namespace arpipe
