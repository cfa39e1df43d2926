// Writes each composited frame (every Nth) as a PNG file named by its position in the stream:
// encoded in memory, written to a temporary name and renamed, so a PNG on disk is always whole.
#pragma once

#include <filesystem>

#include "capture/sinks/write_outage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class PngSink : public FrameSink {
 public:
  explicit PngSink(const PngSinkConfig& config);  // creates the directory; throws std::runtime_error naming it
  ~PngSink() override;
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  uint64_t failures() const { return outage_.failures(); }

  static std::filesystem::path file_name(const std::filesystem::path& dir, uint64_t index);

 private:
  std::filesystem::path dir_;
  int every_;
  int compression_;  // sinks.png.compression
  WriteOutage outage_;
};

}  // namespace arpipe
