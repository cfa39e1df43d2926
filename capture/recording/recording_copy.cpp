#include "capture/recording/recording_copy.h"

#include <algorithm>
#include <optional>
#include <vector>

#include "capture/recording/recording_reader.h"
#include "capture/recording/recording_writer.h"
#include "core/image/pixel_convert.h"

namespace arpipe {

void copy_recording_as(const std::filesystem::path& from, const std::filesystem::path& to, PixelFormat format,
                       size_t frames, const std::string& source) {
  const RecordingReader reader(from);
  RecordingInfo info;
  info.pixel_format = format;
  info.width = reader.info().width;
  info.height = reader.info().height;
  info.source = source;
  RecordingWriter writer(to, info, reader.camera_model());
  const auto& truth = reader.ground_truth();
  std::vector<uint8_t> rgb;
  Frame frame;
  for (size_t i = 0; i < std::min(frames, reader.frame_count()); ++i) {
    reader.read(i, frame);
    to_rgb24(frame, rgb);
    Frame copy = from_rgb24(rgb.data(), frame.width, frame.height, format);
    const RawColour raw = copy.meta.raw;  // how from_rgb24 coded a Bayer copy
    copy.meta = frame.meta;
    copy.meta.raw = raw;
    writer.append(copy, i < truth.size() ? std::optional(truth[i]) : std::nullopt);
  }
  writer.flush();
}

}  // namespace arpipe
