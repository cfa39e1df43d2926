#include "capture/sinks/png_sink.h"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <algorithm>
#include <stdexcept>

#include "capture/sinks/output_path.h"
#include "core/log.h"

namespace arpipe {

PngSink::PngSink(const PngSinkConfig& config) : dir_(config.dir), every_(std::max(1, config.every)) {
  create_output_directory(dir_, "sinks.png.dir");
}

std::string PngSink::describe() const { return "png:" + dir_.string(); }

std::filesystem::path PngSink::file_name(const std::filesystem::path& dir, uint64_t index) {
  return dir / fmt::format("frame_{:06d}.png", index);
}

void PngSink::consume(const FrameContext& ctx) noexcept {
  if (ctx.output.empty() || ctx.input_index % uint64_t(every_) != 0) return;
  const auto path = file_name(dir_, ctx.input_index);
  try {
    const cv::Mat rgb(ctx.output.height, ctx.output.width, CV_8UC3, const_cast<uint8_t*>(ctx.output.data.data()),
                      ctx.output.bytes_per_line);
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    if (!cv::imwrite(path.string(), bgr)) throw std::runtime_error("the PNG encoder refused the file");
  } catch (const std::exception& e) {
    if (failures_++ == 0) log::error("{}: cannot write: {} (further failures are only counted)", path.string(), e.what());
  }
}

}  // namespace arpipe
