#include "capture/live/live_source.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <mutex>

#include <fmt/format.h>

#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

constexpr int kTimeoutsBeforeReopen = 3;

void add(StreamCounters& sum, const StreamCounters& c) {
  sum.frames += c.frames;
  sum.sequence_gaps += c.sequence_gaps;
  sum.timeouts += c.timeouts;
  sum.again += c.again;
  sum.error_buffers += c.error_buffers;
  sum.control_events += c.control_events;
  sum.dequeue_ns += c.dequeue_ns;
  sum.convert_ns += c.convert_ns;
  sum.copies += c.copies;
  sum.frame_allocations += c.frame_allocations;
}

}  // namespace

struct LiveSource::Impl {
  std::string name;
  StreamOpener open;
  std::shared_ptr<const CameraModel> model;
  ReconnectPolicy policy;
  StreamFormat format;

  mutable std::mutex mutex;  // guards stream (interrupt() comes from another thread) and counters
  std::unique_ptr<CameraStream> stream;
  StreamCounters closed_streams;  // counters of the streams already closed
  LiveCounters counters;

  int wake_fd = -1;  // wakes a backoff wait
  int64_t retry_delay_ns = 0;
  int64_t next_retry_ns = 0;

  // Sequence numbers handed on: the stream's plus a base that grows at each reconnect.
  int64_t sequence_base = 0;
  std::optional<uint64_t> last_sequence;
  int64_t last_exposure_start_ns = 0;
  bool rebase = false;
  int consecutive_timeouts = 0;

  void set_stream(std::unique_ptr<CameraStream> s) {
    std::lock_guard lock(mutex);
    stream = std::move(s);
  }

  void close_stream(const std::string& why) {
    std::unique_ptr<CameraStream> old;
    {
      std::lock_guard lock(mutex);
      old = std::move(stream);
      add(closed_streams, old->counters());
      ++counters.disconnects;
    }
    log::error("{}: camera lost: {}; closing it and retrying in {:.0f} ms", name, why, double(policy.first_retry_ns) * 1e-6);
    old.reset();  // stops streaming and closes the device outside the lock
    retry_delay_ns = policy.first_retry_ns;
    next_retry_ns = monotonic_now_ns() + retry_delay_ns;
    rebase = true;
  }

  // Waits for the next retry time (or an interrupt), then tries to reopen the camera once.
  void try_reopen() {
    const int64_t wait_ns = next_retry_ns - monotonic_now_ns();
    if (wait_ns > 0) {
      pollfd fd{wake_fd, POLLIN, 0};
      if (::poll(&fd, 1, int((wait_ns + 999'999) / 1'000'000)) > 0) {
        uint64_t n = 0;
        [[maybe_unused]] const ssize_t r = ::read(wake_fd, &n, sizeof n);
        return;
      }
    }
    try {
      auto reopened = open();
      const StreamFormat& f = reopened->format();
      if (f.format != format.format || f.width != format.width || f.height != format.height)
        throw CameraError(CameraError::Kind::Refused,
                          fmt::format("came back as {} {}x{}, not {} {}x{}", pixel_format_name(f.format), f.width,
                                      f.height, pixel_format_name(format.format), format.width, format.height));
      log::notice("{}: camera back after {} disconnect(s): {}", name, counters.disconnects, reopened->describe());
      set_stream(std::move(reopened));
      std::lock_guard lock(mutex);
      ++counters.reconnects;
    } catch (const std::exception& e) {
      {
        std::lock_guard lock(mutex);
        ++counters.failed_opens;
      }
      retry_delay_ns = std::min(policy.max_retry_ns, retry_delay_ns * 2);
      next_retry_ns = monotonic_now_ns() + retry_delay_ns;
      log::warn("{}: reopening failed: {}; next try in {:.0f} ms", name, e.what(), double(retry_delay_ns) * 1e-6);
    }
  }

  // Gives the frame a sequence number above the last one; after a reconnect, the gap is the frames
  // that fell due while the camera was away (from the exposure times and the frame interval).
  void renumber(Frame& frame) {
    const uint64_t camera_sequence = frame.meta.sequence;
    if (rebase && last_sequence) {
      uint64_t missed = 0;
      const int64_t interval = format.frame_interval_ns;
      const int64_t elapsed = frame.meta.exposure_start_ns - last_exposure_start_ns;
      if (interval > 0 && elapsed > interval)
        missed = uint64_t(std::llround(double(elapsed) / double(interval))) - 1;
      sequence_base = int64_t(*last_sequence + 1 + missed) - int64_t(camera_sequence);
      std::lock_guard lock(mutex);
      counters.frames_missed_while_away += missed;
    }
    rebase = false;
    if (last_sequence && sequence_base + int64_t(camera_sequence) <= int64_t(*last_sequence))
      sequence_base = int64_t(*last_sequence + 1) - int64_t(camera_sequence);  // a camera restarting its count
    frame.meta.sequence = uint64_t(sequence_base + int64_t(camera_sequence));
    last_sequence = frame.meta.sequence;
    last_exposure_start_ns = frame.meta.exposure_start_ns;
  }
};

LiveSource::LiveSource(std::string name, StreamOpener open, std::shared_ptr<const CameraModel> camera_model,
                       ReconnectPolicy policy)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.name = std::move(name);
  s.open = std::move(open);
  s.model = std::move(camera_model);
  s.policy = policy;
  s.stream = s.open();
  s.format = s.stream->format();
  if (s.model && (s.model->width() != s.format.width || s.model->height() != s.format.height))
    throw CameraError(CameraError::Kind::Refused,
                      fmt::format("{}: the camera model is for {}x{} images, the camera streams {}x{}: set "
                                  "source.width and source.height, or calibrate at this size",
                                  s.name, s.model->width(), s.model->height(), s.format.width, s.format.height));
  s.wake_fd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
}

LiveSource::~LiveSource() {
  impl_->set_stream(nullptr);
  if (impl_->wake_fd >= 0) ::close(impl_->wake_fd);
}

std::string LiveSource::describe() const { return impl_->name; }
std::shared_ptr<const CameraModel> LiveSource::camera_model() const { return impl_->model; }
const StreamFormat& LiveSource::format() const { return impl_->format; }

std::optional<int64_t> LiveSource::frame_interval_ns() const {
  if (impl_->format.frame_interval_ns > 0) return impl_->format.frame_interval_ns;
  return std::nullopt;
}

LiveCounters LiveSource::counters() const {
  std::lock_guard lock(impl_->mutex);
  LiveCounters c = impl_->counters;
  c.stream = impl_->closed_streams;
  if (impl_->stream) add(c.stream, impl_->stream->counters());
  return c;
}

std::string LiveSource::describe(const LiveCounters& c) {
  return fmt::format("frames {}, sequence gaps {}, timeouts {}, EAGAIN {}, bad buffers {}, control events {}, "
                     "disconnects {}, reconnects {}, failed reopenings {}, frames missed while away {}",
                     c.stream.frames, c.stream.sequence_gaps, c.stream.timeouts, c.stream.again,
                     c.stream.error_buffers, c.stream.control_events, c.disconnects, c.reconnects, c.failed_opens,
                     c.frames_missed_while_away);
}

std::optional<CaptureCounts> LiveSource::capture_counts() const {
  const StreamCounters s = counters().stream;
  return CaptureCounts{s.frames, s.copies, s.frame_allocations};
}

bool LiveSource::connected() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stream != nullptr;
}

std::string LiveSource::health() const {
  bool connected = false;
  {
    std::lock_guard lock(impl_->mutex);
    connected = impl_->stream != nullptr;
  }
  return fmt::format("{}, {}", connected ? "connected" : "away", describe(counters()));
}

void LiveSource::interrupt() {
  std::lock_guard lock(impl_->mutex);
  if (impl_->stream) impl_->stream->interrupt();
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(impl_->wake_fd, &one, sizeof one);
}

SourceStatus LiveSource::next(Frame& frame) {
  Impl& s = *impl_;
  try {
    if (!s.stream) {
      s.try_reopen();
      return SourceStatus::Retry;
    }
    std::string why;
    switch (s.stream->next(frame, s.policy.frame_timeout_ns, why)) {
      case StreamStatus::Frame:
        s.consecutive_timeouts = 0;
        s.renumber(frame);
        return SourceStatus::Frame;
      case StreamStatus::Timeout:
        // A camera that stays silent (a wedged UVC device) is reopened like one that went away.
        if (++s.consecutive_timeouts >= kTimeoutsBeforeReopen) {
          s.consecutive_timeouts = 0;
          s.close_stream(fmt::format("{} ({} timeouts in a row)", why, kTimeoutsBeforeReopen));
        } else {
          log::warn("{}: {}", s.name, why);
        }
        return SourceStatus::Retry;
      case StreamStatus::Again:
        log::debug("{}: {}", s.name, why);  // EAGAIN storms and bad buffers are counted, not logged each
        return SourceStatus::Retry;
      case StreamStatus::Interrupted:
        return SourceStatus::Retry;
      case StreamStatus::Gone:
        s.close_stream(why);
        return SourceStatus::Retry;
    }
  } catch (const std::exception& e) {  // the per-frame loop never throws
    log::error("{}: {}", s.name, e.what());
  }
  return SourceStatus::Retry;
}

}  // namespace arpipe
