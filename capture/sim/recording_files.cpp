#include "capture/sim/recording_files.h"

#include <fmt/format.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include "capture/panorama/panorama_video_writer.h"
#include "capture/recording/recording_reader.h"
#include "capture/sinks/output_path.h"
#include "capture/sinks/png_encoding.h"
#include "core/image/pixel_convert.h"

namespace arpipe::sim {
namespace {

// Each frame of the recording in `dir`, in order, as packed RGB24 of its size.
template <class Use>
void for_each_rgb_frame(const std::filesystem::path& dir, Use use) {
  const RecordingReader reader(dir);
  Frame frame;
  std::vector<uint8_t> rgb;
  for (size_t i = 0; i < reader.frame_count(); ++i) {
    reader.read(i, frame);
    to_rgb24(frame, rgb);
    use(i, rgb, frame.width, frame.height);
  }
}

}  // namespace

void write_recording_as_video(const std::filesystem::path& dir, const std::filesystem::path& file,
                              const SimCamera& camera) {
  const PanoramaLayout layout = !camera.stereo.enabled ? PanoramaLayout::Equirect
                                : camera.stereo.top_bottom ? PanoramaLayout::EquirectTopBottom
                                                           : PanoramaLayout::EquirectLeftRight;
  PanoramaVideoWriter writer(file, camera.frame_width(), camera.frame_height(), camera.fps, layout);
  for_each_rgb_frame(dir, [&](size_t, const std::vector<uint8_t>& rgb, int width, int) {
    writer.write(rgb.data(), size_t(width) * 3);
  });
  writer.finish();
}

void write_recording_as_pngs(const std::filesystem::path& dir) {
  for_each_rgb_frame(dir, [&](size_t i, const std::vector<uint8_t>& rgb, int width, int height) {
    const std::vector<uint8_t> png = encode_png(from_rgb24(rgb.data(), width, height, PixelFormat::RGB24));
    const std::filesystem::path file = dir / fmt::format("frame_{:06d}.png", i);
    if (const int error = replace_file(file, png))
      throw std::runtime_error(fmt::format("{}: {}", file.string(), std::strerror(error)));
  });
}

}  // namespace arpipe::sim
