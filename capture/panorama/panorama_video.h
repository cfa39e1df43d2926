// A 360° video read frame by frame through FFmpeg's libraries (libavformat, libavcodec, libswscale),
// each frame with its index in presentation order: (pts - the stream's start) x the nominal frame
// rate, rounded, so B-frames (decoded out of order), an MP4 edit list (which moves the start) and
// seeking all give the frame its own index. Software decoding with FFmpeg's frame threads, or the
// board's V4L2 memory-to-memory decoder where it has one.
//
// A hostile file is contained where FFmpeg allows it: only the file protocol, the MP4/MOV and
// Matroska/WebM demuxers and the H.264, HEVC, VP8, VP9 and AV1 decoders are allowed, and the size
// is checked (2:1, at most 16384 across) before a frame is converted.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/config/panorama_config.h"

namespace arpipe {

struct PanoramaVideoFrame {
  int64_t index = 0;     // in presentation order, from 0
  int64_t time_ns = 0;   // presentation time from the stream's start
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;  // 8-bit RGB, row 0 at the top, width * 3 bytes a row
};

class PanoramaVideo {
 public:
  // Opens the file and its best video stream. Throws AssetError naming the file for anything it
  // cannot open or decode, a codec or container outside the list above, or a shape that is not a panorama.
  // layout: how each frame holds the sphere (a stereo pair: both eyes); the file's stereo metadata,
  // where it has some, must say the same. Auto: what the metadata says, else what the shape holds.
  // hardware: try the board's V4L2 memory-to-memory decoder for the codec first (FFmpeg's
  // <codec>_v4l2m2m), software when there is none; describe() names the decoder used.
  explicit PanoramaVideo(const std::filesystem::path& file, PanoramaLayout layout = PanoramaLayout::Auto,
                         bool hardware = false);
  ~PanoramaVideo();
  PanoramaVideo(const PanoramaVideo&) = delete;
  PanoramaVideo& operator=(const PanoramaVideo&) = delete;

  // The layout its frames hold (never Auto).
  PanoramaLayout layout() const;
  int width() const;
  int height() const;
  // The nominal frame rate (the stream's average rate, else its base rate) as num / den.
  int64_t rate_num() const;
  int64_t rate_den() const;
  std::string describe() const;  // "h264 4096 x 2048 at 30/1 frames/s"

  // The next frame in presentation order; false at the end of the stream. A packet or frame that
  // fails to decode, or a frame of another size than the stream's, is skipped and counted
  // (decode_errors), never thrown.
  bool next(PanoramaVideoFrame& out);
  // Seeks so that next() gives the frame of this index (the first one after it when there is none
  // of it exactly). Throws AssetError when the file cannot seek.
  void seek(int64_t index);
  uint64_t decode_errors() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
