// The live HTTP outputs ([sinks.http]): "/" the preview page, "/stream.mjpg" multipart MJPEG,
// "/snapshot.jpg" and "/snapshot.png" the latest frame, "/state" JSON, "/metrics" Prometheus
// text. Read only: nothing over HTTP changes the daemon. Each frame is encoded at most once,
// and not at all while no stream client watches; no client can delay the pipeline or another.
#pragma once

#include <deque>
#include <memory>
#include <mutex>

#include "capture/sinks/http/http_counters.h"
#include "capture/sinks/http/http_server.h"
#include "capture/sinks/http/jpeg_encoder.h"
#include "capture/sinks/http/listen_socket.h"
#include "capture/sinks/http/live_frame_board.h"
#include "core/config/config.h"
#include "core/pipeline/frame_sink.h"
#include "core/pipeline/pipeline_status.h"
#include "core/system/thread_cpu.h"

namespace arpipe {

class HttpSink : public FrameSink, private HttpHandler {
 public:
  // Binds and starts serving at once (the page answers, the stream shows the placeholder until the
  // first frame). Throws std::runtime_error naming the address when it cannot listen.
  HttpSink(const HttpSinkConfig& config, StatusProvider status);
  ~HttpSink() override;
  std::string describe() const override;
  void consume(const FrameContext& ctx) noexcept override;
  void consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept override;

  // Where it listens, the kernel's port included (tests listen on port 0).
  const std::string& bound() const { return socket_->bound(); }
  HttpCounters counters() const;

 private:
  HttpReply get(std::string_view path) noexcept override;
  HttpReply snapshot(bool png);
  bool camera_away() const;
  std::shared_ptr<const LiveJpeg> placeholder();

  HttpSinkConfig config_;
  StatusProvider status_;
  int64_t started_ns_ = 0;
  LiveFrameBoard board_;
  JpegEncoder encoder_;  // the sink thread's
  mutable std::mutex counters_mutex_;
  HttpCounters counters_;
  std::deque<int64_t> recent_published_ns_;  // for recent_fps
  CpuByPart cpu_by_part_;  // /metrics' CPU counters, carried from one scrape to the next
  std::mutex placeholder_mutex_;
  std::shared_ptr<const LiveJpeg> placeholder_;
  int placeholder_width_ = 0, placeholder_height_ = 0;
  std::shared_ptr<ListenSocket> socket_;  // shared with the sink a reload makes on the same address
  std::unique_ptr<HttpServer> server_;  // last: stopped first, while everything it reads still exists
};

}  // namespace arpipe
