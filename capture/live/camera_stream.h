// One open, streaming live camera (V4L2 or libcamera). A LiveSource owns one at a time and
// replaces it when the camera goes away; nothing here retries.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "core/frame.h"

namespace arpipe {

// Opening or configuring a camera failed. what() names the camera and says why; a refused
// negotiation lists what the camera offers.
class CameraError : public std::runtime_error {
 public:
  enum class Kind {
    Missing,  // no such camera now (unplugged, wrong path or id): worth retrying
    Refused,  // the camera cannot do what the config asks: retrying will not help
    Failed,   // any other failure while opening or starting
  };
  CameraError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// What was negotiated with the camera: what every frame of this stream has.
struct StreamFormat {
  PixelFormat format = PixelFormat::RGB24;  // of the frames handed on (MJPEG arrives decoded)
  std::string camera_format;                // what the camera sends: "YUYV", "MJPG", ...
  int width = 0;
  int height = 0;
  int64_t frame_interval_ns = 0;            // 0 when the camera does not say
};

enum class StreamStatus {
  Frame,        // frame filled
  Timeout,      // no frame within the timeout
  Again,        // woke up without a frame (EAGAIN, a buffer the driver flagged bad, an event only)
  Interrupted,  // interrupt() was called
  Gone,         // the camera disappeared or failed for good: close this stream and reopen
};

// Per-stream counts, summed by LiveSource over reconnects.
struct StreamCounters {
  uint64_t frames = 0;
  uint64_t sequence_gaps = 0;  // frames the driver's sequence numbers say were lost
  uint64_t timeouts = 0;
  uint64_t again = 0;          // EAGAIN wake-ups without a frame
  uint64_t error_buffers = 0;  // buffers the driver flagged as corrupt (requeued, not handed on)
  uint64_t control_events = 0; // exposure or gain changes the camera reported
  // Where the time of the frames handed on went (for bench/capture_path): taking the buffer from
  // the driver and giving it back (DQBUF + QBUF, or libcamera's request completion and requeue),
  // and copying or decoding it into the Frame with its metadata.
  int64_t dequeue_ns = 0;
  int64_t convert_ns = 0;
  // Passes over a frame's bytes from the driver's buffer into the Frame (one a frame on a copying
  // path; MJPEG's decode is not counted), and frames whose memory had to be allocated because the
  // Frame handed in held too little (none in steady state once frames are recycled).
  uint64_t copies = 0;
  uint64_t frame_allocations = 0;
};

class CameraStream {
 public:
  virtual ~CameraStream() = default;  // stops streaming, frees the buffers, closes the camera
  virtual std::string describe() const = 0;
  virtual const StreamFormat& format() const = 0;
  // Waits up to timeout_ns for the next frame and fills `frame` (pixels in format().format,
  // metadata normalised per docs/DESIGN.md; sequence as the camera numbers it). Never throws; a
  // status other than Frame comes with a reason in `why`.
  virtual StreamStatus next(Frame& frame, int64_t timeout_ns, std::string& why) = 0;
  // Makes a blocked next() return Interrupted soon (from another thread).
  virtual void interrupt() = 0;
  virtual StreamCounters counters() const = 0;
};

}  // namespace arpipe
