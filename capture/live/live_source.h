// A FrameSource over a live camera: opens it through a StreamOpener, and when the camera goes
// away closes it, retries with exponential backoff and resumes, without the daemon restarting.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "capture/live/camera_stream.h"
#include "core/config/config.h"
#include "core/pipeline/frame_source.h"

namespace arpipe {

// Opens the camera and starts streaming; throws CameraError.
using StreamOpener = std::function<std::unique_ptr<CameraStream>()>;

struct ReconnectPolicy {
  int64_t frame_timeout_ns = 1'000'000'000;
  int64_t first_retry_ns = 100'000'000;
  int64_t max_retry_ns = 5'000'000'000;
};

// What happened to the camera over the source's life (logged, and shown by arpipe record).
struct LiveCounters {
  StreamCounters stream;           // summed over every stream opened
  uint64_t disconnects = 0;        // streams closed because the camera went away
  uint64_t reconnects = 0;         // successful reopenings after a disconnect
  uint64_t failed_opens = 0;       // reopening attempts that failed
  uint64_t frames_missed_while_away = 0;  // estimated from the time away and the frame interval
};

class LiveSource : public FrameSource {
 public:
  // Opens the camera once (a CameraError propagates: the caller decides, e.g. a config error at
  // start-up). `camera_model` may be null (recording only); its size must match the stream's.
  LiveSource(std::string name, StreamOpener open, std::shared_ptr<const CameraModel> camera_model,
             ReconnectPolicy policy);
  ~LiveSource() override;

  std::string describe() const override;
  bool is_live() const override { return true; }
  std::shared_ptr<const CameraModel> camera_model() const override;
  std::optional<int64_t> frame_interval_ns() const override;
  // Frames carry sequence numbers that keep rising across reconnects, with a gap of the frames
  // estimated lost while away, so the pipeline counts them as dropped.
  SourceStatus next(Frame& frame) override;
  void interrupt() override;
  std::string health() const override;
  bool connected() const override;
  std::optional<CaptureCounts> capture_counts() const override;

  const StreamFormat& format() const;  // as first negotiated
  LiveCounters counters() const;
  // "connected|away, disconnects D, reconnects R, ...": every counter, for logs and status.
  static std::string describe(const LiveCounters& counters);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Builds the live source the config names (source.type "v4l2" or "libcamera"); throws
// CameraError (camera missing or refusing) or ConfigError (bad camera model file).
std::unique_ptr<LiveSource> make_live_source(const SourceConfig& config);

}  // namespace arpipe
