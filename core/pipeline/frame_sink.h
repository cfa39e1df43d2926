// Where composited frames go: PNG files, Y4M video, recordings, per-frame results. Sink thread.
#pragma once

#include <string>

#include "core/pipeline/frame_context.h"

namespace arpipe {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual std::string describe() const = 0;
  // The run is up (setup succeeded, frames may come): outputs of the previous run may now be
  // replaced. Sinks also take their first frame, or a flush(), to mean this, so calling it is optional.
  virtual void run_started() noexcept {}
  // Per frame. Must not throw: a write failure is logged and counted, and later frames still come.
  virtual void consume(const FrameContext& ctx) noexcept = 0;
  // Makes everything written so far durable (end of stream, SIGTERM).
  virtual void flush() noexcept {}
};

}  // namespace arpipe
