#include "capture/sinks/y4m_sink.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <numeric>

#include "core/image/pixel_convert.h"
#include "core/log.h"

namespace arpipe {

namespace {

std::span<const uint8_t> bytes_of(std::string_view text) {
  return {reinterpret_cast<const uint8_t*>(text.data()), text.size()};
}

}  // namespace

Y4mSink::Y4mSink(const Y4mSinkConfig& config)
    : path_(config.path),
      file_(path_, "sinks.y4m.path"),
      outage_(path_.string(), "the video ends at its last complete frame") {}

// Never committed (the start failed): OutputFile removes this run's file and the previous one stays.
Y4mSink::~Y4mSink() { outage_.report_at_end(); }

std::string Y4mSink::describe() const { return "y4m:" + path_.string(); }

void Y4mSink::run_started() noexcept {
  std::string error;
  if (!file_.committed() && !file_.commit(error))
    log::error("{}: cannot replace it with this run's video: {}; it is in {}", path_.string(), error,
               file_.temporary().string());
}

std::string Y4mSink::header(const FrameContext& first) const {
  // Frame rate as a ratio of integers from the camera's frame interval (30 fps when unknown).
  int64_t num = 30, den = 1;
  if (first.camera.meta.frame_duration_ns > 0) {
    num = 1'000'000'000;
    den = first.camera.meta.frame_duration_ns;
    const int64_t g = std::gcd(num, den);
    num /= g;
    den /= g;
  }
  return fmt::format("YUV4MPEG2 W{} H{} F{}:{} Ip A1:1 C420jpeg\n", width_, height_, num, den);
}

void Y4mSink::consume(const FrameContext& ctx) noexcept {
  run_started();
  if (ctx.output.empty()) return;
  try {
    if (header_.empty()) {
      // 4:2:0 needs even sizes; an odd last row or column is left out rather than the frame.
      width_ = ctx.output.width & ~1;
      height_ = ctx.output.height & ~1;
      header_ = header(ctx);
    }
    if ((ctx.output.width & ~1) != width_ || (ctx.output.height & ~1) != height_) {
      if (size_failures_++ == 0)
        log::error("{}: cannot write frame {}: frame size {}x{} differs from the video's {}x{} (further frames of "
                   "another size are only counted)",
                   path_.string(), ctx.input_index, ctx.output.width, ctx.output.height, width_, height_);
      return;
    }
    const uint8_t* rgb = ctx.output.data.data();
    const size_t packed_row = size_t(ctx.output.width) * 3;
    if (ctx.output.bytes_per_line != packed_row) {  // the converter wants rows without padding
      packed_.resize(packed_row * size_t(ctx.output.height));
      for (int y = 0; y < ctx.output.height; ++y)
        std::memcpy(packed_.data() + size_t(y) * packed_row, rgb + size_t(y) * ctx.output.bytes_per_line, packed_row);
      rgb = packed_.data();
    }
    rgb24_to_i420(rgb, ctx.output.width, width_, height_, i420_);
  } catch (const std::exception& e) {  // memory for the conversion
    outage_.failed(ctx.input_index, e.what());
    return;
  }
  // Header (the first time), marker and picture as one record: a failed write is cut back to the
  // last complete frame, so the frames after it are where the format puts them.
  const int error = file_.append({bytes_of(header_written_ ? std::string_view() : std::string_view(header_)),
                                  bytes_of("FRAME\n"), std::span<const uint8_t>(i420_)});
  if (error) {
    // A reader that left got part of the stream; one that opens the FIFO next starts with a header.
    if (error == EPIPE) header_written_ = false;
    outage_.failed(ctx.input_index, std::strerror(error));
    return;
  }
  header_written_ = true;
  ++frames_written_;
  outage_.succeeded(ctx.input_index);
}

void Y4mSink::flush() noexcept {
  run_started();
  file_.sync();
}

}  // namespace arpipe
