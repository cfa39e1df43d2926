#include "capture/sinks/http/mjpeg_stream.h"

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

// How often a waiting stream looks whether the camera went away, and how often it repeats the
// placeholder while it is (so that a client sees it and its connection stays alive).
constexpr std::chrono::milliseconds kWaitStep{250};
constexpr int64_t kPlaceholderEveryNs = 1'000'000'000;

}  // namespace

MjpegStream::MjpegStream(MjpegStreamSource source) : source_(std::move(source)) {
  source_.board.add_watcher();
  // The newest frame at once if it is encoded already (another client watches), else the next one.
  const uint64_t latest = source_.board.latest_serial();
  last_serial_ = latest > 0 ? latest - 1 : 0;
}

MjpegStream::~MjpegStream() { source_.board.remove_watcher(); }

std::string MjpegStream::part(const LiveJpeg& jpeg, int64_t now_ns) {
  std::string headers = fmt::format("--{}\r\nContent-Type: image/jpeg\r\nContent-Length: {}\r\n", kBoundary, jpeg.bytes.size());
  if (jpeg.placeholder) {
    headers += "X-Arpipe-Placeholder: camera away\r\n";
  } else {
    // Origin: where the latency counts from, on the daemon's CLOCK_MONOTONIC (a client on the same
    // host can take its own end-to-end latency from it).
    headers += fmt::format(
        "X-Arpipe-Sequence: {}\r\nX-Arpipe-Exposure-Start-Ns: {}\r\nX-Arpipe-Origin-Ns: {}\r\nX-Arpipe-Latency-Ms: {:.3f}\r\n",
        jpeg.sequence, jpeg.exposure_start_ns, jpeg.origin_ns, double(now_ns - jpeg.origin_ns) * 1e-6);
  }
  std::string out;
  out.reserve(headers.size() + jpeg.bytes.size() + 4);
  out += headers;
  out += "\r\n";
  out += jpeg.bytes;
  out += "\r\n";
  return out;
}

bool MjpegStream::next_part() {
  const int64_t waiting_since = monotonic_now_ns();
  while (!source_.board.closed()) {
    if (std::shared_ptr<const LiveJpeg> jpeg = source_.board.wait_for_jpeg(last_serial_, kWaitStep)) {
      last_serial_ = jpeg->serial;
      part_ = part(*jpeg, monotonic_now_ns());
      pending_origin_ns_ = jpeg->origin_ns;
      last_sent_ = std::move(jpeg);
      return true;
    }
    const int64_t now = monotonic_now_ns();
    if (source_.camera_away() && now - last_placeholder_ns_ >= kPlaceholderEveryNs) {
      last_placeholder_ns_ = now;
      if (std::shared_ptr<const LiveJpeg> placeholder = source_.placeholder()) {
        part_ = part(*placeholder, now);
        pending_origin_ns_ = 0;
        return true;
      }
    }
    // Frames slower than the keepalive (a dark scene's long exposures): the last one again, so
    // the server does not take the client for idle. Its latency is not counted twice.
    if (last_sent_ && now - waiting_since >= std::chrono::nanoseconds(source_.keepalive).count()) {
      part_ = part(*last_sent_, now);
      pending_origin_ns_ = 0;
      return true;
    }
  }
  return false;
}

ssize_t MjpegStream::read(char* buf, size_t max) {
  if (offset_ == part_.size()) {
    // libmicrohttpd asks for more once it has handed the previous bytes to the socket.
    if (pending_origin_ns_ != 0) source_.delivered(double(monotonic_now_ns() - pending_origin_ns_) * 1e-9);
    pending_origin_ns_ = 0;
    part_.clear();
    offset_ = 0;
    if (!next_part()) return -1;
  }
  const size_t n = std::min(max, part_.size() - offset_);
  std::memcpy(buf, part_.data() + offset_, n);
  offset_ += n;
  return ssize_t(n);
}

}  // namespace arpipe
