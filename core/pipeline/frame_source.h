// Where frames come from: replay, simulator, V4L2, libcamera. Runs on the capture thread.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "core/frame.h"
#include "core/geometry/camera_model.h"

namespace arpipe {

enum class SourceStatus { Frame, EndOfStream, Retry };

struct CaptureCounts {
  uint64_t frames = 0;
  uint64_t copies = 0;             // full passes over a frame's bytes out of the driver's buffer
  uint64_t frame_allocations = 0;  // frames whose memory was allocated rather than reused
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual std::string describe() const = 0;
  // Live sources drop the oldest queued frame when processing falls behind; replay blocks.
  virtual bool is_live() const = 0;
  // The camera model the frames were taken with (a recording carries its own).
  virtual std::shared_ptr<const CameraModel> camera_model() const = 0;
  // The time from one frame's start to the next's, when the source knows it (a recording's frame
  // duration or spacing, a live camera's negotiated rate): no exposure can be longer.
  virtual std::optional<int64_t> frame_interval_ns() const { return std::nullopt; }
  // Blocks until the next frame (paced as configured). Never throws for a per-frame problem:
  // returns Retry after logging (camera gone, timeout) or EndOfStream at the end of a recording.
  virtual SourceStatus next(Frame& frame) = 0;
  // Asks a blocked next() to return soon (from another thread).
  virtual void interrupt() {}
  // What a live source has lived through ("disconnects 1, reconnects 1, timeouts 2"), for the
  // daemon's status; empty when there is nothing to say. Thread-safe.
  virtual std::string health() const { return {}; }
  // False while a live camera is away (unplugged, being reopened). Thread-safe.
  virtual bool connected() const { return true; }
  // What a camera's capture path did with its frames' bytes, when it counts (the V4L2 source):
  // copies from the driver's buffers and frames whose memory had to be allocated. Thread-safe.
  virtual std::optional<CaptureCounts> capture_counts() const { return std::nullopt; }
};

}  // namespace arpipe
