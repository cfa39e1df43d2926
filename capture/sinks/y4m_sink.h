// Writes composited frames as one YUV4MPEG2 (Y4M) video, 4:2:0, which ffmpeg and mpv play.
#pragma once

#include <filesystem>
#include <vector>

#include "capture/sinks/output_path.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class Y4mSink : public FrameSink {
 public:
  explicit Y4mSink(const Y4mSinkConfig& config);  // opens the file; throws std::runtime_error naming it
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;
  uint64_t frames_written() const { return frames_written_; }

 private:
  bool write_header(const FrameContext& first);
  std::filesystem::path path_;
  OutputFile file_;
  int width_ = 0, height_ = 0;
  uint64_t frames_written_ = 0;
  uint64_t failures_ = 0;
  bool write_failed_ = false;
  std::vector<uint8_t> packed_;  // the frame without row padding, when it has some
  std::vector<uint8_t> i420_;
};

}  // namespace arpipe
