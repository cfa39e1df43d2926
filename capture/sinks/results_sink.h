// Writes one JSON line per frame with what the pipeline found: tracking state, pose, the anchor
// point's pixel, timings and skip reasons. End-to-end tests and people read it; lines are flushed.
#pragma once

#include <filesystem>

#include "capture/sinks/output_path.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class ResultsSink : public FrameSink {
 public:
  explicit ResultsSink(const ResultsSinkConfig& config);  // throws std::runtime_error naming the file
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;

  // The JSON line for one frame (without the newline).
  static std::string to_json_line(const FrameContext& ctx);

 private:
  std::filesystem::path path_;
  OutputFile file_;
  uint64_t failures_ = 0;
};

}  // namespace arpipe
