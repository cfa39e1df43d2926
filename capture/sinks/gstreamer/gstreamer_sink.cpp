#include "capture/sinks/gstreamer/gstreamer_sink.h"

#include <fmt/format.h>
#include <gst/app/gstappsrc.h>

#include <chrono>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <thread>

#include "capture/sinks/gstreamer/gst_handles.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

struct GstreamerSink::Gst {
  GstElementHandle pipeline;
  GstElementHandle appsrc;
  GstBusHandle bus;
};

namespace {

constexpr const char* kKey = "sinks.gstreamer.pipeline";

// GStreamer's own stride for packed RGB: rows padded to 4 bytes.
size_t gst_rgb_stride(int width) { return (size_t(width) * 3 + 3) & ~size_t(3); }

}  // namespace

GstreamerSink::GstreamerSink(const GstreamerSinkConfig& config)
    : pipeline_text_(config.pipeline),
      eos_timeout_ms_(config.eos_timeout_ms),
      restart_ms_(config.restart_ms),
      gst_(build()) {}

std::unique_ptr<GstreamerSink::Gst> GstreamerSink::build() const {
  ensure_gstreamer_initialised();
  auto gst = std::make_unique<Gst>();
  GError* error = nullptr;
  GstElement* parsed = gst_parse_launch_full(pipeline_text_.c_str(), nullptr, GST_PARSE_FLAG_FATAL_ERRORS, &error);
  if (error) {
    const std::string message = error->message;
    g_error_free(error);
    if (parsed) gst_object_unref(parsed);
    throw std::runtime_error(fmt::format("{} = \"{}\": {}", kKey, pipeline_text_, message));
  }
  // A single element comes back as itself, not in a bin: a pipeline of only an appsrc feeds nothing.
  if (!GST_IS_BIN(parsed)) {
    gst_object_unref(parsed);
    throw std::runtime_error(fmt::format("{} = \"{}\": needs an appsrc named \"arpipe\" and something it feeds", kKey, pipeline_text_));
  }
  gst->pipeline.reset(parsed);
  gst->appsrc.reset(gst_bin_get_by_name(GST_BIN(parsed), "arpipe"));
  if (!gst->appsrc || !GST_IS_APP_SRC(gst->appsrc.get()))
    throw std::runtime_error(fmt::format("{} = \"{}\": no appsrc named \"arpipe\" (start it with \"appsrc name=arpipe ! ...\")", kKey, pipeline_text_));
  // Time-stamped buffers. appsrc's own blocking push could wait for ever on a stalled pipeline (and
  // with it the daemon's stop), so wait_for_room() waits, at most eos_timeout_ms.
  g_object_set(gst->appsrc.get(), "format", GST_FORMAT_TIME, "block", FALSE, "is-live", FALSE, "do-timestamp", FALSE, nullptr);
  gst->bus.reset(gst_element_get_bus(gst->pipeline.get()));
  // Left in NULL: a file sink opens (and truncates) its file on the way to READY, and the last
  // run's file must survive a start that fails later on.
  return gst;
}

GstreamerSink::~GstreamerSink() {
  if (gst_->pipeline) gst_element_set_state(gst_->pipeline.get(), GST_STATE_NULL);
}

std::string GstreamerSink::describe() const {
  constexpr size_t kShown = 60;
  return "gstreamer:" + (pipeline_text_.size() > kShown ? pipeline_text_.substr(0, kShown) + "..." : pipeline_text_);
}

void GstreamerSink::fail(const std::string& why) noexcept {
  if (!failed_) {
    if (restart_ms_ > 0)
      log::error("{}: the GStreamer pipeline stopped: {}; building it again every {} ms (sinks.gstreamer.restart_ms), frames "
                 "meanwhile only counted", kKey, why, restart_ms_);
    else
      log::error("{}: the GStreamer pipeline stopped: {}; later frames are only counted (sinks.gstreamer.restart_ms = 0)", kKey, why);
    failed_since_ns_ = monotonic_now_ns();
  }
  failed_ = true;
  gst_element_set_state(gst_->pipeline.get(), GST_STATE_NULL);
  if (restart_ms_ > 0) restart_at_ns_ = monotonic_now_ns() + int64_t(restart_ms_) * 1'000'000;
}

// A new pipeline from the same text, its time starting again at its first frame. A file sink's
// file is opened (truncated) again: restart_ms is for network outputs (docs/OPERATIONS.md).
void GstreamerSink::restart() noexcept {
  if (!failed_ || ended_ || restart_ms_ <= 0 || monotonic_now_ns() < restart_at_ns_) return;
  gst_element_set_state(gst_->pipeline.get(), GST_STATE_NULL);
  try {
    gst_ = build();
  } catch (const std::exception&) {  // the same text built at start: only memory or plugins gone
    restart_at_ns_ = monotonic_now_ns() + int64_t(restart_ms_) * 1'000'000;
    return;
  }
  ++restarts_;
  failed_ = false;
  playing_ = false;
  width_ = height_ = 0;
  frames_since_start_ = 0;
  last_pts_ns_ = -1;
  run_started();
  if (!failed_)
    log::info("{}: the GStreamer pipeline runs again after {:.1f} s", kKey, double(monotonic_now_ns() - failed_since_ns_) * 1e-9);
}

void GstreamerSink::run_started() noexcept {
  if (playing_ || failed_) return;
  playing_ = true;
  // Files and connections open here, once the run is up (a failed start leaves the last run's file).
  if (gst_element_set_state(gst_->pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    GstMessageHandle message{gst_bus_pop_filtered(gst_->bus.get(), GST_MESSAGE_ERROR)};
    fail(message ? gst_message_text(message.get()) : "cannot start playing");
  }
}

void GstreamerSink::check_bus() noexcept {
  while (GstMessageHandle message{gst_bus_pop_filtered(gst_->bus.get(), GstMessageType(GST_MESSAGE_ERROR | GST_MESSAGE_WARNING))}) {
    if (GST_MESSAGE_TYPE(message.get()) == GST_MESSAGE_WARNING) {
      log::warn("{}: {}", kKey, gst_message_text(message.get()));
      continue;
    }
    fail(gst_message_text(message.get()));
  }
}

void GstreamerSink::set_caps(const Frame& first) noexcept {
  width_ = first.width;
  height_ = first.height;
  // The frame rate from the camera's frame interval (variable, 0/1, when unknown): encoders use it for
  // their rate control; the buffers' own times are the exposures'.
  int64_t num = 0, den = 1;
  if (first.meta.frame_duration_ns > 0) {
    num = 1'000'000'000;
    den = first.meta.frame_duration_ns;
    const int64_t g = std::gcd(num, den);
    num /= g;
    den /= g;
  }
  GstCaps* caps = gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "RGB", "width", G_TYPE_INT, width_, "height",
                                      G_TYPE_INT, height_, "framerate", GST_TYPE_FRACTION, int(num), int(den),
                                      "pixel-aspect-ratio", GST_TYPE_FRACTION, 1, 1, nullptr);
  gst_app_src_set_caps(GST_APP_SRC(gst_->appsrc.get()), caps);
  gst_caps_unref(caps);
  max_queued_bytes_ = 3 * gst_rgb_stride(width_) * size_t(height_);
  g_object_set(gst_->appsrc.get(), "max-bytes", guint64(2 * max_queued_bytes_), nullptr);
}

bool GstreamerSink::wait_for_room() noexcept {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(eos_timeout_ms_);
  while (gst_app_src_get_current_level_bytes(GST_APP_SRC(gst_->appsrc.get())) >= max_queued_bytes_) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    check_bus();
    if (failed_) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

void GstreamerSink::consume(const FrameContext& ctx) noexcept { push(ctx, nullptr); }

void GstreamerSink::consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept { push(*ctx, ctx); }

void GstreamerSink::push(const FrameContext& ctx, const std::shared_ptr<const FrameContext>& shared) noexcept {
  run_started();
  check_bus();
  restart();
  if (ctx.output.empty()) return;
  if (failed_ || ended_) {
    ++failures_;
    return;
  }
  const Frame& frame = ctx.output;
  if (width_ == 0) set_caps(frame);
  if (frame.width != width_ || frame.height != height_) {
    if (failures_++ == 0)
      log::error("{}: frame {} is {}x{}, the stream {}x{}: frames of another size are left out (and counted)", kKey,
                 ctx.input_index, frame.width, frame.height, width_, height_);
    return;
  }
  // Three frames inside the pipeline at most: a slow encoder backs up into this sink's queue (which
  // drops or waits as the source says), not into memory.
  if (!wait_for_room()) {
    if (!failed_ && stalls_++ == 0)
      log::error("{}: the pipeline took no frame for sinks.gstreamer.eos_timeout_ms = {}: frame {} left out (further ones "
                 "only counted)", kKey, eos_timeout_ms_, ctx.input_index);
    ++failures_;
    return;
  }
  const size_t stride = gst_rgb_stride(width_);
  const size_t size = stride * size_t(height_);
  GstBuffer* buffer = nullptr;
  if (shared && frame.bytes_per_line == stride && frame.data.size() >= size) {
    // Zero copy: GStreamer holds the frame (shared, never changed) until it is done with the bytes.
    auto* keep = new std::shared_ptr<const FrameContext>(shared);
    buffer = gst_buffer_new_wrapped_full(GST_MEMORY_FLAG_READONLY, const_cast<uint8_t*>(frame.data.data()), size, 0, size, keep,
                                         [](gpointer p) { delete static_cast<std::shared_ptr<const FrameContext>*>(p); });
  } else {
    buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
    GstMapInfo map;
    if (!buffer || !gst_buffer_map(buffer, &map, GST_MAP_WRITE)) {
      if (buffer) gst_buffer_unref(buffer);
      ++failures_;
      return;
    }
    const size_t row = size_t(width_) * 3;
    for (int y = 0; y < height_; ++y) {
      std::memcpy(map.data + size_t(y) * stride, frame.data.data() + size_t(y) * frame.bytes_per_line, row);
      std::memset(map.data + size_t(y) * stride + row, 0, stride - row);
    }
    gst_buffer_unmap(buffer, &map);
    ++frames_copied_;
  }
  // Presentation time: the exposure start, from the first frame's; never backwards (a muxer refuses that).
  const int64_t exposure = frame.meta.exposure_start_ns;
  if (frames_since_start_ == 0) first_exposure_ns_ = exposure;
  int64_t pts = exposure - first_exposure_ns_;
  if (pts <= last_pts_ns_) pts = last_pts_ns_ + 1;
  last_pts_ns_ = pts;
  GST_BUFFER_PTS(buffer) = GstClockTime(pts);
  GST_BUFFER_DTS(buffer) = GST_CLOCK_TIME_NONE;
  const int64_t duration = frame.meta.frame_duration_ns;
  GST_BUFFER_DURATION(buffer) = duration > 0 ? GstClockTime(duration) : GST_CLOCK_TIME_NONE;
  GST_BUFFER_OFFSET(buffer) = ctx.input_index;
  // Takes the buffer.
  const GstFlowReturn flow = gst_app_src_push_buffer(GST_APP_SRC(gst_->appsrc.get()), buffer);
  if (flow != GST_FLOW_OK) {
    ++failures_;
    check_bus();
    if (!failed_) fail(fmt::format("the pipeline refused frame {} ({})", ctx.input_index, gst_flow_get_name(flow)));
    return;
  }
  ++frames_pushed_;
  ++frames_since_start_;
}

void GstreamerSink::flush() noexcept {
  run_started();
  if (ended_ || failed_) return;
  ended_ = true;
  // End of stream, then wait for it to come out at the sinks: a muxer writes its index then.
  gst_app_src_end_of_stream(GST_APP_SRC(gst_->appsrc.get()));
  GstMessageHandle message{gst_bus_timed_pop_filtered(gst_->bus.get(), GstClockTime(eos_timeout_ms_) * GST_MSECOND,
                                                      GstMessageType(GST_MESSAGE_EOS | GST_MESSAGE_ERROR))};
  if (!message)
    log::error("{}: the pipeline did not finish within sinks.gstreamer.eos_timeout_ms = {}; its outputs may be incomplete", kKey,
               eos_timeout_ms_);
  else if (GST_MESSAGE_TYPE(message.get()) == GST_MESSAGE_ERROR)
    fail(gst_message_text(message.get()));
  gst_element_set_state(gst_->pipeline.get(), GST_STATE_NULL);
}

}  // namespace arpipe
