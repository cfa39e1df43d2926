// One client's multipart MJPEG stream (/stream.mjpg): each part the newest frame's JPEG, which
// the sink encoded once for every client; a client that falls behind skips frames rather than
// queueing them. While the camera is away the parts are a placeholder that says so.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "capture/sinks/http/http_server.h"
#include "capture/sinks/http/live_frame_board.h"

namespace arpipe {

struct MjpegStreamSource {
  LiveFrameBoard& board;
  // True while the camera is away (disconnected, or no frame for a while).
  std::function<bool()> camera_away;
  // The placeholder's JPEG (shared, made once per size).
  std::function<std::shared_ptr<const LiveJpeg>()> placeholder;
  // A camera frame's last byte was handed on to the socket, this long after the end of its exposure.
  std::function<void(double latency_seconds)> delivered;
  // The longest a client goes without a byte: the server drops a connection idle for its timeout,
  // so a slow camera's stream repeats its last part after this long (half the timeout).
  std::chrono::milliseconds keepalive{5000};
};

class MjpegStream : public HttpStreamBody {
 public:
  static constexpr const char* kBoundary = "arpipeframe";
  // Counts itself among the board's watchers while it lives.
  explicit MjpegStream(MjpegStreamSource source);
  ~MjpegStream() override;
  ssize_t read(char* buf, size_t max) override;

  // The part for one JPEG: boundary, headers (sequence, exposure start, latency so far), bytes.
  static std::string part(const LiveJpeg& jpeg, int64_t now_ns);

 private:
  // Waits for the next part; false when the server is stopping.
  bool next_part();

  MjpegStreamSource source_;
  uint64_t last_serial_ = 0;
  std::string part_;
  size_t offset_ = 0;
  int64_t pending_origin_ns_ = 0;  // the part being sent is a camera frame's: its latency origin
  int64_t last_placeholder_ns_ = 0;
  std::shared_ptr<const LiveJpeg> last_sent_;  // repeated when nothing new comes for `keepalive`
};

}  // namespace arpipe
