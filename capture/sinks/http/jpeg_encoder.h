// Encodes RGB24 frames as baseline JPEG with libjpeg-turbo (MJPEG parts and snapshots). One
// encoder per thread: the library's handle is not shared.
#pragma once

#include <string>

#include "core/frame.h"

namespace arpipe {

class JpegEncoder {
 public:
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  // quality in [1, 100]; 4:2:0 chroma, as browsers and MJPEG readers expect. Throws
  // std::runtime_error when the frame is not RGB24 or the library fails.
  std::string encode(const Frame& rgb, int quality);

 private:
  void* handle_ = nullptr;  // tjhandle
};

}  // namespace arpipe
