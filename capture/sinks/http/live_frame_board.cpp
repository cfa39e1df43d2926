#include "capture/sinks/http/live_frame_board.h"

#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

void LiveFrameBoard::publish(std::shared_ptr<const FrameContext> frame, std::shared_ptr<const LiveJpeg> jpeg) {
  {
    std::lock_guard lock(mutex_);
    frame_ = std::move(frame);
    ++serial_;
    published_ns_ = monotonic_now_ns();
    if (jpeg) jpeg_ = std::move(jpeg);
  }
  changed_.notify_all();
}

std::shared_ptr<const FrameContext> LiveFrameBoard::latest_frame() const {
  std::lock_guard lock(mutex_);
  return frame_;
}

uint64_t LiveFrameBoard::latest_serial() const {
  std::lock_guard lock(mutex_);
  return serial_;
}

int64_t LiveFrameBoard::latest_published_ns() const {
  std::lock_guard lock(mutex_);
  return published_ns_;
}

std::shared_ptr<const LiveJpeg> LiveFrameBoard::latest_jpeg() const {
  std::lock_guard lock(mutex_);
  return jpeg_;
}

std::shared_ptr<const LiveJpeg> LiveFrameBoard::wait_for_jpeg(uint64_t after, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || (jpeg_ && jpeg_->serial > after); });
  if (closed_ || !jpeg_ || jpeg_->serial <= after) return nullptr;
  return jpeg_;
}

void LiveFrameBoard::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool LiveFrameBoard::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void LiveFrameBoard::add_watcher() {
  std::lock_guard lock(mutex_);
  ++watchers_;
}

void LiveFrameBoard::remove_watcher() {
  std::lock_guard lock(mutex_);
  --watchers_;
}

int LiveFrameBoard::watchers() const {
  std::lock_guard lock(mutex_);
  return watchers_;
}

}  // namespace arpipe
