// Records the composited frames (RGB24) as a format-v1 recording, with the camera's metadata.
// Never overwrites a recording: a directory that holds one fails setup.
#pragma once

#include <memory>

#include "capture/sinks/write_outage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class RecordingWriter;

class RecordingSink : public FrameSink {
 public:
  // Checks that config.path holds no recording yet (throws std::runtime_error naming the path and
  // sinks.recording.path when it does); the recording is created at the first frame, so a start
  // that fails leaves nothing behind.
  explicit RecordingSink(const RecordingSinkConfig& config);
  ~RecordingSink() override;
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  void flush() noexcept override;
  uint64_t failures() const { return outage_.failures(); }

 private:
  RecordingSinkConfig config_;
  std::unique_ptr<RecordingWriter> writer_;
  bool creation_failed_ = false;  // the recording could not be created: the rest of the run goes on without it
  WriteOutage outage_;
};

}  // namespace arpipe
