// Writes composited frames as one YUV4MPEG2 (Y4M) video, 4:2:0, which ffmpeg and mpv play: whole
// frames only, through a full disk (cut back, retried) and a FIFO whose reader leaves (header resent).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "capture/sinks/output_file.h"
#include "capture/sinks/write_outage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class Y4mSink : public FrameSink {
 public:
  // Opens this run's file beside the previous one, which it replaces once the run is up (OutputFile);
  // a FIFO is opened directly. Throws std::runtime_error naming the file.
  explicit Y4mSink(const Y4mSinkConfig& config);
  ~Y4mSink() override;
  std::string describe() const override;
  void run_started() noexcept override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;
  uint64_t frames_written() const { return frames_written_; }
  uint64_t failures() const { return outage_.failures() + size_failures_; }

 private:
  std::string header(const FrameContext& first) const;
  std::filesystem::path path_;
  OutputFile file_;
  WriteOutage outage_;
  int width_ = 0, height_ = 0;  // of the video: the first frame's, even
  std::string header_;          // empty until the first frame
  bool header_written_ = false; // the stream (or, after a broken pipe, the new reader) has the header
  uint64_t frames_written_ = 0;
  uint64_t size_failures_ = 0;
  std::vector<uint8_t> packed_;  // the frame without row padding, when it has some
  std::vector<uint8_t> i420_;
};

}  // namespace arpipe
