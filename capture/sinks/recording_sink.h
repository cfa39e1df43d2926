// Records the composited frames (RGB24) as a format-v1 recording, with the camera's metadata.
#pragma once

#include <memory>

#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class RecordingWriter;

class RecordingSink : public FrameSink {
 public:
  explicit RecordingSink(const RecordingSinkConfig& config);  // the recording is created at the first frame
  ~RecordingSink() override;
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;

 private:
  RecordingSinkConfig config_;
  std::unique_ptr<RecordingWriter> writer_;
  uint64_t failures_ = 0;
};

}  // namespace arpipe
