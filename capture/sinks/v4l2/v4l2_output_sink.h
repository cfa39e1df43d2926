// Writes the composite to a V4L2 output device ([sinks.v4l2], a v4l2loopback node) so that other
// programs see it as a camera: MMAP streaming, YUYV or RGB24, buffer timestamps = exposure starts.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture/sinks/write_outage.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"

namespace arpipe {

class V4l2OutputSink : public FrameSink {
 public:
  // Buffers asked of the driver: enough that a reader a frame or two behind never holds up the sink.
  static constexpr uint32_t kBuffers = 4;

  // Opens the device and checks that it is a streaming V4L2 video output. Throws
  // std::runtime_error naming sinks.v4l2.device. Format and size are set with the first frame.
  explicit V4l2OutputSink(const V4l2SinkConfig& config);
  ~V4l2OutputSink() override;
  std::string describe() const override;
  // Never blocks for longer than dequeue_wait_ns(): a frame for which no buffer came back in time
  // is dropped and counted. A device that fails is closed and opened again at most once a second.
  void consume(const FrameContext& ctx) noexcept override;

  uint64_t frames_written() const { return frames_written_.load(); }
  uint64_t frames_dropped() const { return frames_dropped_.load(); }  // no buffer came back in time
  uint64_t failures() const { return failures_.load(); }              // errors, refused formats, other sizes

  // How long a frame waits for the device to hand a buffer back: two frame intervals, within
  // [50 ms, 1 s]; 100 ms when the interval is unknown.
  static int64_t dequeue_wait_ns(int64_t frame_duration_ns);

 private:
  struct Mapping {
    void* data = nullptr;
    size_t length = 0;
  };

  // Opens the device and checks its capabilities; "" or why not.
  std::string open_device();
  // S_FMT (the first frame's size), S_PARM, REQBUFS, QUERYBUF + mmap, STREAMON; "" or why not.
  std::string start_stream(const Frame& frame);
  void close_device() noexcept;
  // A free buffer's index, waiting at most `wait_ns` for the device to hand one back; -1 when none
  // came (why empty) or the device failed (why says how).
  int take_buffer(int64_t wait_ns, std::string& why);
  void fill(const Frame& frame, uint8_t* dst) const;
  void failed(uint64_t index, const std::string& why) noexcept;

  std::filesystem::path device_;
  V4l2OutputFormat format_;
  uint32_t fourcc_;
  int fd_ = -1;
  bool streaming_ = false;
  int64_t retry_at_ns_ = 0;  // a failed device is opened again from then on
  int width_ = 0, height_ = 0;                     // of the stream (the first frame's; even width for YUYV)
  uint32_t bytes_per_line_ = 0, size_image_ = 0;   // as the driver answered
  std::vector<Mapping> mappings_;
  std::vector<uint32_t> free_;                     // buffers the sink holds (not queued)
  WriteOutage outage_;
  std::atomic<uint64_t> frames_written_{0}, frames_dropped_{0}, failures_{0};
};

}  // namespace arpipe
