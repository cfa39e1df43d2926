#include "capture/sinks/y4m_sink.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <system_error>

#include "capture/sinks/output_path.h"
#include "core/image/pixel_convert.h"
#include "core/log.h"

namespace arpipe {

Y4mSink::Y4mSink(const Y4mSinkConfig& config) : path_(config.path), file_(path_, "sinks.y4m.path") {}

std::string Y4mSink::describe() const { return "y4m:" + path_.string(); }

bool Y4mSink::write_header(const FrameContext& first) {
  // 4:2:0 needs even sizes; an odd last row or column is left out rather than the frame.
  width_ = first.output.width & ~1;
  height_ = first.output.height & ~1;
  // Frame rate as a ratio of integers from the camera's frame interval (30 fps when unknown).
  int64_t num = 30, den = 1;
  if (first.camera.meta.frame_duration_ns > 0) {
    num = 1'000'000'000;
    den = first.camera.meta.frame_duration_ns;
    const int64_t g = std::gcd(num, den);
    num /= g;
    den /= g;
  }
  const std::string header = fmt::format("YUV4MPEG2 W{} H{} F{}:{} Ip A1:1 C420jpeg\n", width_, height_, num, den);
  return std::fwrite(header.data(), 1, header.size(), file_.get()) == header.size();
}

void Y4mSink::consume(const FrameContext& ctx) noexcept {
  if (write_failed_ || ctx.output.empty()) return;
  try {
    if (frames_written_ == 0 && !write_header(ctx)) throw std::system_error(errno, std::generic_category(), "header");
    if ((ctx.output.width & ~1) != width_ || (ctx.output.height & ~1) != height_)
      throw std::runtime_error(fmt::format("frame size {}x{} differs from the video's {}x{}", ctx.output.width,
                                           ctx.output.height, width_, height_));
    const uint8_t* rgb = ctx.output.data.data();
    const size_t packed_row = size_t(ctx.output.width) * 3;
    if (ctx.output.bytes_per_line != packed_row) {  // the converter wants rows without padding
      packed_.resize(packed_row * size_t(ctx.output.height));
      for (int y = 0; y < ctx.output.height; ++y)
        std::memcpy(packed_.data() + size_t(y) * packed_row, rgb + size_t(y) * ctx.output.bytes_per_line, packed_row);
      rgb = packed_.data();
    }
    rgb24_to_i420(rgb, ctx.output.width, width_, height_, i420_);
    static const char kFrame[] = "FRAME\n";
    if (std::fwrite(kFrame, 1, 6, file_.get()) != 6 || std::fwrite(i420_.data(), 1, i420_.size(), file_.get()) != i420_.size())
      throw std::system_error(errno, std::generic_category(), "frame");
    ++frames_written_;
  } catch (const std::system_error& e) {
    // Part of the frame may be in the file: anything written after it would be misread as shifted
    // frames, so the video ends with the last complete frame and the rest of the run goes on without it.
    ++failures_;
    write_failed_ = true;
    log::error("{}: cannot write frame {}: {}; the video stops after {} frames", path_.string(), ctx.input_index,
               e.what(), frames_written_);
  } catch (const std::exception& e) {
    if (failures_++ == 0) log::error("{}: cannot write frame {}: {}", path_.string(), ctx.input_index, e.what());
  }
}

void Y4mSink::flush() noexcept { file_.sync(); }

}  // namespace arpipe
