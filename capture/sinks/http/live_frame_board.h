// The latest composited frame, shared between the HTTP sink (which publishes each frame) and the
// server's connection threads (which read it): the frame for snapshots and state, its JPEG for
// the MJPEG streams, encoded once however many clients watch. A client that falls behind skips to
// the newest frame; nothing here waits for a client.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "core/pipeline/frame_context.h"

namespace arpipe {

struct LiveJpeg {
  uint64_t serial = 0;            // publication order (a looping replay repeats sequence numbers)
  uint64_t sequence = 0;          // the camera's frame sequence number
  int64_t exposure_start_ns = 0;  // CLOCK_MONOTONIC, as the frame's metadata
  int64_t origin_ns = 0;          // FrameContext::latency_origin_ns(); 0 for a placeholder
  int64_t encoded_ns = 0;         // when the encoding finished
  bool placeholder = false;       // "camera away", not a camera frame
  std::string bytes;
};

class LiveFrameBoard {
 public:
  // The newest frame; jpeg (its encoding) may be null when no stream was watching.
  void publish(std::shared_ptr<const FrameContext> frame, std::shared_ptr<const LiveJpeg> jpeg);
  std::shared_ptr<const FrameContext> latest_frame() const;
  // The serial the next publish() gets minus one: which frame latest_frame() is.
  uint64_t latest_serial() const;
  // CLOCK_MONOTONIC of the last publish(); 0 before the first.
  int64_t latest_published_ns() const;
  std::shared_ptr<const LiveJpeg> latest_jpeg() const;
  // Blocks until a JPEG newer than serial `after` is published (returns it), the timeout passes or
  // the board is closed (returns null).
  std::shared_ptr<const LiveJpeg> wait_for_jpeg(uint64_t after, std::chrono::milliseconds timeout);
  // Wakes every waiter for good (the server is stopping).
  void close();
  bool closed() const;

  // MJPEG clients watching: while there are none, frames are not encoded.
  void add_watcher();
  void remove_watcher();
  int watchers() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const FrameContext> frame_;
  std::shared_ptr<const LiveJpeg> jpeg_;
  uint64_t serial_ = 0;
  int64_t published_ns_ = 0;
  int watchers_ = 0;
  bool closed_ = false;
};

}  // namespace arpipe
