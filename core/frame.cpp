#include "core/frame.h"

namespace arpipe {

std::string_view timestamp_meaning_name(TimestampMeaning meaning) {
  switch (meaning) {
    case TimestampMeaning::StartOfExposure: return "start_of_exposure";
    case TimestampMeaning::EndOfFrame: return "end_of_frame";
    case TimestampMeaning::EndOfExposure: return "end_of_exposure";
    case TimestampMeaning::Sensor: return "sensor";
  }
  return "?";
}

bool timestamp_meaning_from_name(std::string_view name, TimestampMeaning& out) {
  for (auto m : {TimestampMeaning::StartOfExposure, TimestampMeaning::EndOfFrame, TimestampMeaning::EndOfExposure,
                 TimestampMeaning::Sensor}) {
    if (timestamp_meaning_name(m) == name) {
      out = m;
      return true;
    }
  }
  return false;
}

int64_t exposure_start_from_raw(int64_t raw_ns, TimestampMeaning meaning, int64_t exposure_ns, int64_t readout_ns,
                                int64_t offset_ns) {
  int64_t start = raw_ns;
  // End of frame is when the last row finished: it started exposing readout_ns after the first row.
  if (meaning == TimestampMeaning::EndOfFrame) start = raw_ns - exposure_ns - readout_ns;
  // The first row's end of exposure: it started exposure_ns before.
  if (meaning == TimestampMeaning::EndOfExposure) start = raw_ns - exposure_ns;
  return start + offset_ns;
}

bool Frame::reshape(PixelFormat new_format, int new_width, int new_height, size_t new_bytes_per_line) {
  format = new_format;
  width = new_width;
  height = new_height;
  bytes_per_line = new_bytes_per_line ? new_bytes_per_line : min_bytes_per_line(new_format, new_width);
  const size_t bytes = image_bytes(format, width, height, bytes_per_line);
  const bool allocates = data.capacity() < bytes;
  data.resize(bytes);
  return allocates;
}

Frame Frame::allocate(PixelFormat format, int width, int height) {
  Frame f;
  f.format = format;
  f.width = width;
  f.height = height;
  f.bytes_per_line = min_bytes_per_line(format, width);
  f.data.resize(image_bytes(format, width, height, f.bytes_per_line));
  return f;
}

}  // namespace arpipe
