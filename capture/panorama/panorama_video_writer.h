// A 360° video written frame by frame through FFmpeg's libraries: H.264 (libx264) in MP4, 4:2:0,
// with Google's Spherical Video V2 metadata (sv3d: equirectangular; st3d: mono, top/bottom or
// side by side) so that 360° players, and source.panorama's "auto" layout, know what it holds.
// What `arpipe simulate --video` writes from a LENSMODEL_LONLAT camera's frames.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "core/config/panorama_config.h"

namespace arpipe {

class PanoramaVideoWriter {
 public:
  // width x height: the whole frame (both eyes for a stereo layout), even; fps > 0; crf: x264's
  // constant rate factor (0 lossless, 18 visually lossless, 23 its default). Throws
  // std::runtime_error naming the file when the encoder or the file cannot be opened.
  PanoramaVideoWriter(const std::filesystem::path& file, int width, int height, double fps, PanoramaLayout layout,
                      int crf = 18);
  ~PanoramaVideoWriter();  // finishes the file if finish() was not called (errors are then logged)
  PanoramaVideoWriter(const PanoramaVideoWriter&) = delete;
  PanoramaVideoWriter& operator=(const PanoramaVideoWriter&) = delete;

  // One frame: 8-bit RGB, width x height, row 0 at the top. Throws std::runtime_error on a failure.
  void write(const uint8_t* rgb, size_t bytes_per_line);
  // Drains the encoder and writes the MP4's index. Throws std::runtime_error on a failure.
  void finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
