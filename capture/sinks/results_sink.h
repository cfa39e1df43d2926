// Writes one JSON line per frame with what the pipeline found: tracking state, pose, the anchor
// point's pixel, timings and skip reasons. Whole lines only, each handed to the kernel as it is made.
#pragma once

#include <filesystem>
#include <nlohmann/json_fwd.hpp>

#include "capture/sinks/output_file.h"
#include "capture/sinks/write_outage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class ResultsSink : public FrameSink {
 public:
  // Opens this run's file beside the previous one, which it replaces once the run is up (OutputFile);
  // throws std::runtime_error naming the file.
  explicit ResultsSink(const ResultsSinkConfig& config);
  ~ResultsSink() override;
  std::string describe() const override;
  void run_started() noexcept override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;
  uint64_t failures() const { return outage_.failures() + encode_failures_; }

  // What the pipeline found for one frame, as a JSON object (the live outputs' /state embeds it).
  static nlohmann::json to_json(const FrameContext& ctx);
  // The JSON line for one frame (without the newline).
  static std::string to_json_line(const FrameContext& ctx);

 private:
  std::filesystem::path path_;
  OutputFile file_;
  WriteOutage outage_;
  uint64_t encode_failures_ = 0;
};

}  // namespace arpipe
