// libFuzzer target: the panorama source's readers on every input, as a still (PNG/JPEG through
// capture/image_file, then the 2:1 check and the pyramid) and as a video (FFmpeg's MP4/MOV and
// Matroska/WebM demuxers and the decoders capture/panorama/panorama_video allows, a few frames and
// a seek), and both as stereo pairs. Anything bad must be an AssetError; a frame that comes out must
// be a whole panorama.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "capture/panorama/equirect_image.h"
#include "capture/panorama/panorama_video.h"
#include "core/scene/asset_error.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

namespace {

void load_still(const uint8_t* data, size_t size) {
  try {
    arpipe::EquirectImage image = arpipe::EquirectImage::load(arpipe::fuzz::write_temp_file("panorama.png", data, size), 1.0);
    ARPIPE_FUZZ_CHECK(image.width() == 2 * image.height(), "a 2:1 still");
    image.build_levels(image.levels());
    ARPIPE_FUZZ_CHECK(image.built_levels() == image.levels(), "the whole pyramid built");
    uint8_t rgb[3];
    image.sample(image.levels() - 1, -1.5f, -0.5f, rgb);  // across the seam and over the pole
  } catch (const arpipe::AssetError&) {
  }
  // As a stereo pair, each layout: two eyes of one 2:1 size.
  for (const arpipe::PanoramaLayout layout : {arpipe::PanoramaLayout::EquirectTopBottom, arpipe::PanoramaLayout::EquirectLeftRight}) {
    try {
      const std::vector<arpipe::EquirectImage> eyes =
          arpipe::EquirectImage::load_eyes(arpipe::fuzz::write_temp_file("panorama.png", data, size), 1.0, layout);
      ARPIPE_FUZZ_CHECK(eyes.size() == 2 && eyes[0].width() == 2 * eyes[0].height() && eyes[1].width() == eyes[0].width() &&
                            eyes[1].height() == eyes[0].height(),
                        "two 2:1 eyes of one size");
    } catch (const arpipe::AssetError&) {
    }
  }
}

void read_video(const uint8_t* data, size_t size) {
  try {
    arpipe::PanoramaVideo video(arpipe::fuzz::write_temp_file("panorama.mp4", data, size));
    arpipe::PanoramaVideoFrame frame;
    for (int k = 0; k < 3 && video.next(frame); ++k)
      ARPIPE_FUZZ_CHECK(frame.width == 2 * frame.height && frame.rgb.size() == size_t(frame.width) * size_t(frame.height) * 3,
                        "a whole 2:1 frame");
    video.seek(1);
    (void)video.next(frame);
  } catch (const arpipe::AssetError&) {
  }
  try {  // a top/bottom pair: 1:1 frames
    arpipe::PanoramaVideo video(arpipe::fuzz::write_temp_file("panorama.mp4", data, size), arpipe::PanoramaLayout::EquirectTopBottom);
    arpipe::PanoramaVideoFrame frame;
    if (video.next(frame))
      ARPIPE_FUZZ_CHECK(frame.width == frame.height && frame.rgb.size() == size_t(frame.width) * size_t(frame.height) * 3,
                        "a whole 1:1 pair");
  } catch (const arpipe::AssetError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  load_still(data, size);
  read_video(data, size);
  return 0;
}
