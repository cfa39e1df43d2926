// FFmpeg's words for one of its error codes (av_strerror), for the panorama video reader and writer.
#pragma once

extern "C" {
#include <libavutil/error.h>
}

#include <string>

namespace arpipe {

inline std::string ffmpeg_error(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

}  // namespace arpipe
