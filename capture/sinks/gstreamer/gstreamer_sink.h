// Feeds the composite into a GStreamer pipeline ([sinks.gstreamer] pipeline = "appsrc name=arpipe
// ! ..."): a file, an RTSP server (rtspclientsink), a hardware encoder. Frames go in as RGB with
// presentation times from their exposures (the first frame's exposure start is time 0), without a
// copy where the frame's rows have GStreamer's stride.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class GstreamerSink : public FrameSink {
 public:
  // Builds the pipeline (every element exists). Its outputs (a file sink's file, a connection) open
  // only once the run is up, so a failed start leaves the last run's file. Throws
  // std::runtime_error naming sinks.gstreamer.pipeline when it does not parse or has no appsrc
  // named "arpipe".
  explicit GstreamerSink(const GstreamerSinkConfig& config);
  ~GstreamerSink() override;
  std::string describe() const override;
  void run_started() noexcept override;
  void consume(const FrameContext& ctx) noexcept override;
  void consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept override;
  // End of stream: the pipeline finishes its outputs (a muxer writes its index) within eos_timeout_ms.
  void flush() noexcept override;

  uint64_t frames_pushed() const { return frames_pushed_; }
  uint64_t frames_copied() const { return frames_copied_; }
  uint64_t failures() const { return failures_; }
  uint64_t restarts() const { return restarts_; }  // pipelines built again after an error (restart_ms)

 private:
  // The one push path: `shared` keeps the frame alive while GStreamer holds its bytes (no copy);
  // without it the bytes are copied.
  void push(const FrameContext& ctx, const std::shared_ptr<const FrameContext>& shared) noexcept;
  void set_caps(const Frame& first) noexcept;  // the stream's caps from its first frame
  // Waits until the pipeline holds fewer than three frames, at most eos_timeout_ms; false if not.
  bool wait_for_room() noexcept;
  void check_bus() noexcept;  // a pipeline error stops the sink (logged once, frames then counted)
  void fail(const std::string& why) noexcept;
  // After an error, with restart_ms > 0: builds and starts the pipeline again once restart_ms passed.
  void restart() noexcept;

  std::string pipeline_text_;
  int eos_timeout_ms_;
  int restart_ms_;
  struct Gst;  // the pipeline, its appsrc and bus (GStreamer's headers stay out of this one)
  // Parses the pipeline text; throws std::runtime_error naming sinks.gstreamer.pipeline.
  std::unique_ptr<Gst> build() const;
  std::unique_ptr<Gst> gst_;
  bool playing_ = false;
  bool failed_ = false;
  bool ended_ = false;
  int width_ = 0, height_ = 0;  // of the stream: the first frame's
  int64_t first_exposure_ns_ = 0;
  int64_t last_pts_ns_ = -1;
  uint64_t frames_pushed_ = 0;
  uint64_t frames_since_start_ = 0;  // of this pipeline (a restart starts its time again)
  uint64_t restarts_ = 0;
  int64_t restart_at_ns_ = 0;
  int64_t failed_since_ns_ = 0;
  uint64_t frames_copied_ = 0;
  uint64_t failures_ = 0;
  uint64_t stalls_ = 0;
  size_t max_queued_bytes_ = 0;
};

}  // namespace arpipe
