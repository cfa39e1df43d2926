#include "capture/sinks/latest_frame_sink.h"

namespace arpipe {

void LatestFrame::set(std::shared_ptr<const FrameContext> frame) {
  std::lock_guard lock(mutex_);
  frame_ = std::move(frame);
}

std::shared_ptr<const FrameContext> LatestFrame::get() const {
  std::lock_guard lock(mutex_);
  return frame_;
}

}  // namespace arpipe
