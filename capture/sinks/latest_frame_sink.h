// Keeps the newest composited frame for whoever asks later (arpipe ctl snapshot): no copy, the
// frame is shared with the other sinks; only the newest is held.
#pragma once

#include <memory>
#include <mutex>

#include "core/pipeline/frame_sink.h"

namespace arpipe {

class LatestFrame {
 public:
  void set(std::shared_ptr<const FrameContext> frame);
  std::shared_ptr<const FrameContext> get() const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const FrameContext> frame_;
};

class LatestFrameSink : public FrameSink {
 public:
  explicit LatestFrameSink(std::shared_ptr<LatestFrame> latest) : latest_(std::move(latest)) {}
  std::string describe() const override { return "the newest frame, for arpipe ctl snapshot"; }
  void consume(const FrameContext& ctx) noexcept override { consume_shared(std::make_shared<const FrameContext>(ctx)); }
  void consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept override { latest_->set(ctx); }

 private:
  std::shared_ptr<LatestFrame> latest_;
};

}  // namespace arpipe
