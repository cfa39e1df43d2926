// Writes each composited frame (every Nth) as a PNG file named by its position in the stream.
#pragma once

#include <filesystem>

#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class PngSink : public FrameSink {
 public:
  explicit PngSink(const PngSinkConfig& config);  // creates the directory; throws std::runtime_error naming it
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  uint64_t failures() const { return failures_; }

  static std::filesystem::path file_name(const std::filesystem::path& dir, uint64_t index);

 private:
  std::filesystem::path dir_;
  int every_;
  uint64_t failures_ = 0;
};

}  // namespace arpipe
