#include "capture/sinks/http/http_sink.h"

#include <fmt/format.h>

#include "capture/sinks/http/live_state.h"
#include "capture/sinks/http/mjpeg_stream.h"
#include "capture/sinks/http/placeholder_frame.h"
#include "capture/sinks/http/preview_page.h"
#include "capture/sinks/png_encoding.h"
#include "core/log.h"
#include "core/pipeline/monotonic_clock.h"

namespace arpipe {

namespace {

constexpr size_t kRecentFrames = 30;  // recent_fps over about a second at 30 frames/s

ListenAddress parsed(const HttpSinkConfig& config) {
  std::string why;
  if (std::optional<ListenAddress> address = parse_listen_address(config.listen, why)) return *address;
  throw std::runtime_error(fmt::format("sinks.http.listen = \"{}\": expected {}", config.listen, why));
}

HttpReply text_reply(unsigned status, std::string body) {
  HttpReply reply;
  reply.status = status;
  reply.body = std::move(body);
  return reply;
}

}  // namespace

HttpSink::HttpSink(const HttpSinkConfig& config, StatusProvider status)
    : config_(config), status_(std::move(status)), started_ns_(monotonic_now_ns()), socket_(ListenSocket::shared(parsed(config))) {
  HttpLimits limits;
  limits.max_clients = config.max_clients;
  limits.idle_timeout_s = std::max(1, (config.client_timeout_ms + 999) / 1000);
  HttpHandler& handler = *this;
  server_ = std::make_unique<HttpServer>(*socket_, limits, handler);
  log::info("sinks.http: serving the preview on {} (/, /stream.mjpg, /snapshot.jpg, /state, /metrics)", socket_->bound());
}

HttpSink::~HttpSink() {
  board_.close();   // waiting streams end
  server_.reset();  // connections closed, their threads joined
}

std::string HttpSink::describe() const { return fmt::format("HTTP on {}", socket_->bound()); }

void HttpSink::consume(const FrameContext& ctx) noexcept {
  consume_shared(std::make_shared<const FrameContext>(ctx));
}

void HttpSink::consume_shared(const std::shared_ptr<const FrameContext>& ctx) noexcept {
  std::shared_ptr<LiveJpeg> jpeg;
  const bool watched = board_.watchers() > 0;
  if (watched && !ctx->output.empty()) {
    const int64_t start = monotonic_now_ns();
    try {
      jpeg = std::make_shared<LiveJpeg>();
      jpeg->bytes = encoder_.encode(ctx->output, config_.jpeg_quality);
      jpeg->serial = board_.latest_serial() + 1;  // this sink's thread is the only publisher
      jpeg->sequence = ctx->camera.meta.sequence;
      jpeg->exposure_start_ns = ctx->camera.meta.exposure_start_ns;
      jpeg->origin_ns = ctx->latency_origin_ns();
      jpeg->encoded_ns = monotonic_now_ns();
    } catch (const std::exception& e) {
      jpeg.reset();
      std::lock_guard lock(counters_mutex_);
      if (counters_.encode_failures++ == 0)
        log::error("sinks.http: cannot encode frame {}: {} (further failures are only counted)", ctx->input_index, e.what());
    }
    if (jpeg) {
      std::lock_guard lock(counters_mutex_);
      ++counters_.jpeg_encodes;
      counters_.jpeg_encode_seconds += double(jpeg->encoded_ns - start) * 1e-9;
    }
  }
  board_.publish(ctx, jpeg);
  std::lock_guard lock(counters_mutex_);
  if (!watched) ++counters_.frames_not_encoded;
  recent_published_ns_.push_back(monotonic_now_ns());
  if (recent_published_ns_.size() > kRecentFrames) recent_published_ns_.pop_front();
}

HttpCounters HttpSink::counters() const {
  std::lock_guard lock(counters_mutex_);
  HttpCounters c = counters_;
  c.stream_clients = board_.watchers();
  c.requests = server_ ? server_->requests() : 0;
  if (recent_published_ns_.size() >= 2) {
    const double span = double(recent_published_ns_.back() - recent_published_ns_.front()) * 1e-9;
    // Frames that stopped coming count down towards zero instead of freezing the last rate.
    const double since_last = double(monotonic_now_ns() - recent_published_ns_.back()) * 1e-9;
    c.recent_fps = span > 0 ? double(recent_published_ns_.size() - 1) / (span + since_last) : 0;
  }
  return c;
}

bool HttpSink::camera_away() const {
  if (status_ && !status_().source_connected) return true;
  // No frame for a while, or none yet a while after the start.
  const int64_t last = board_.latest_published_ns();
  return monotonic_now_ns() - (last ? last : started_ns_) > int64_t(config_.camera_away_ms) * 1'000'000;
}

std::shared_ptr<const LiveJpeg> HttpSink::placeholder() {
  const std::shared_ptr<const FrameContext> latest = board_.latest_frame();
  const bool sized = latest && !latest->output.empty();
  const int width = sized ? latest->output.width : 640, height = sized ? latest->output.height : 480;
  std::lock_guard lock(placeholder_mutex_);
  if (!placeholder_ || placeholder_width_ != width || placeholder_height_ != height) {
    auto made = std::make_shared<LiveJpeg>();
    made->placeholder = true;
    try {
      JpegEncoder encoder;
      made->bytes = encoder.encode(placeholder_frame(width, height, "camera away: waiting for frames"), config_.jpeg_quality);
    } catch (const std::exception& e) {
      log::error("sinks.http: cannot make the placeholder picture: {}", e.what());
      return nullptr;
    }
    placeholder_ = std::move(made);
    placeholder_width_ = width;
    placeholder_height_ = height;
  }
  return placeholder_;
}

HttpReply HttpSink::snapshot(bool png) {
  const std::shared_ptr<const FrameContext> frame = board_.latest_frame();
  if (!frame || frame->output.empty()) return text_reply(503, "no frame yet\n");
  HttpReply reply;
  reply.headers = {{"X-Arpipe-Sequence", fmt::format("{}", frame->camera.meta.sequence)},
                   {"X-Arpipe-Exposure-Start-Ns", fmt::format("{}", frame->camera.meta.exposure_start_ns)}};
  if (png) {
    const std::vector<uint8_t> bytes = encode_png(frame->output);
    reply.content_type = "image/png";
    reply.body.assign(bytes.begin(), bytes.end());
    return reply;
  }
  reply.content_type = "image/jpeg";
  // The stream's encoding of this very frame when there is one; else one made for this request.
  const std::shared_ptr<const LiveJpeg> streamed = board_.latest_jpeg();
  if (streamed && streamed->serial == board_.latest_serial() && streamed->sequence == frame->camera.meta.sequence) {
    reply.body = streamed->bytes;
    return reply;
  }
  thread_local std::unique_ptr<JpegEncoder> encoder;
  if (!encoder) encoder = std::make_unique<JpegEncoder>();
  reply.body = encoder->encode(frame->output, config_.jpeg_quality);
  return reply;
}

HttpReply HttpSink::get(std::string_view path) noexcept {
  try {
    if (path == "/" || path == "/index.html") {
      HttpReply reply;
      reply.content_type = "text/html; charset=utf-8";
      reply.body = std::string(preview_page_html());
      reply.headers = {{"Content-Security-Policy", "default-src 'self'; style-src 'unsafe-inline'; script-src 'unsafe-inline'"}};
      return reply;
    }
    if (path == "/stream.mjpg") {
      HttpReply reply;
      reply.content_type = fmt::format("multipart/x-mixed-replace; boundary={}", MjpegStream::kBoundary);
      reply.stream = std::make_unique<MjpegStream>(MjpegStreamSource{
          board_, [this] { return camera_away(); }, [this] { return placeholder(); },
          [this](double seconds) {
            std::lock_guard lock(counters_mutex_);
            counters_.stream_latency_seconds.add(seconds);
          },
          std::chrono::milliseconds(config_.client_timeout_ms / 2)});
      return reply;
    }
    if (path == "/snapshot.jpg" || path == "/snapshot.png") return snapshot(path.ends_with(".png"));
    if (path == "/state" || path == "/metrics") {
      const PipelineStatus status = status_ ? status_() : PipelineStatus{};
      const bool away = camera_away();
      HttpReply reply;
      if (path == "/metrics") {
        reply.content_type = "text/plain; version=0.0.4; charset=utf-8";
        HttpCounters c = counters();
        c.cpu_seconds_by_part = cpu_by_part_.update();
        c.process_cpu_seconds = process_cpu_seconds();
        reply.body = live_metrics_text(status, away, c);
      } else {
        const std::shared_ptr<const FrameContext> latest = board_.latest_frame();
        const double age = latest ? double(monotonic_now_ns() - board_.latest_published_ns()) * 1e-9 : 0;
        reply.content_type = "application/json";
        reply.body = live_state_json(status, latest.get(), age, away, counters());
      }
      return reply;
    }
    return text_reply(404, "not found: the paths are /, /stream.mjpg, /snapshot.jpg, /snapshot.png, /state, /metrics\n");
  } catch (const std::exception& e) {
    log::warn("sinks.http: {}: {}", path, e.what());
    return text_reply(500, "internal error\n");
  }
}

}  // namespace arpipe
