// libFuzzer target: the two PNG/JPEG decoders of the project, on every input: the MJPEG decoder
// of UVC webcams (capture/v4l2 MjpegDecoder, libjpeg-turbo) and the simulator's image textures
// (capture/sim PlaneTexture, OpenCV's imread). The MJPEG decoder must never throw for bad data;
// a bad texture must be an AssetError.
#include <turbojpeg.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "capture/sim/sim_textures.h"
#include "capture/v4l2/mjpeg_decoder.h"
#include "core/frame.h"
#include "core/scene/asset_error.h"
#include "tests/fuzz/fuzz_check.h"
#include "tests/fuzz/fuzz_temp_dir.h"

namespace {

// The size a V4L2 stream would have negotiated: the frame's own when a UVC camera could send it,
// else a common one, so that the size-mismatch path runs too.
void stream_size_for(const uint8_t* data, size_t size, int& width, int& height) {
  width = 640;
  height = 480;
  tjhandle handle = tjInitDecompress();
  int w = 0, h = 0, subsampling = 0, colorspace = 0;
  if (size > 0 && tjDecompressHeader3(handle, data, static_cast<unsigned long>(size), &w, &h, &subsampling,
                                      &colorspace) == 0 &&
      w > 0 && h > 0 && w <= 4096 && h <= 4096) {
    width = w;
    height = h;
  }
  tjDestroy(handle);
}

void decode_mjpeg(const uint8_t* data, size_t size) {
  static arpipe::MjpegDecoder decoder;  // one per stream, reused frame after frame
  int width = 0, height = 0;
  stream_size_for(data, size, width, height);
  arpipe::Frame frame;
  std::string why;
  if (decoder.decode(data, size, width, height, frame, why)) {
    ARPIPE_FUZZ_CHECK(frame.width == width && frame.height == height, "the stream's size");
    ARPIPE_FUZZ_CHECK(frame.data.size() >= frame.bytes_per_line * static_cast<size_t>(height), "whole rows");
  } else {
    ARPIPE_FUZZ_CHECK(!why.empty(), "a reason for a rejected frame");
  }
}

void load_texture(const uint8_t* data, size_t size) {
  arpipe::sim::SimMaterial material;
  material.texture.kind = arpipe::sim::SimTexture::Kind::Image;
  material.texture.image_path = arpipe::fuzz::write_temp_file("texture.png", data, size);
  try {
    const arpipe::sim::PlaneTexture texture(material, "fuzz");
    for (const double u : {0.0, 0.5, 1.0}) (void)texture.reflectance(u, 1.0 - u);
  } catch (const arpipe::AssetError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  decode_mjpeg(data, size);
  load_texture(data, size);
  return 0;
}
