// Where composited frames go: PNG files, Y4M video, recordings, per-frame results, live outputs.
// Each sink runs on its own thread behind its own queue (core/pipeline/sink_worker.h).
#pragma once

#include <memory>
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
  // The same, for a sink that keeps the frame after it returns (the live outputs keep the latest):
  // the frame is shared with the other sinks and never changes.
  virtual void consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept { consume(*ctx); }
  // Makes everything written so far durable (end of stream, SIGTERM).
  virtual void flush() noexcept {}
};

}  // namespace arpipe
