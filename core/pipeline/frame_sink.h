// Where composited frames go: PNG files, Y4M video, recordings, per-frame results. Sink thread.
#pragma once

#include <string>

#include "core/pipeline/frame_context.h"

namespace arpipe {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual std::string describe() const = 0;
  // Per frame. Must not throw: a write failure is logged and counted, and later frames still come.
  virtual void consume(const FrameContext& ctx) noexcept = 0;
  // Makes everything written so far durable (end of stream, SIGTERM).
  virtual void flush() noexcept {}
};

}  // namespace arpipe
