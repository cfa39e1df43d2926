#include "capture/sinks/png_sink.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "capture/sinks/output_path.h"

namespace arpipe {

PngSink::PngSink(const PngSinkConfig& config)
    : dir_(config.dir), every_(std::max(1, config.every)), compression_(config.compression), outage_(dir_.string(), "no partial PNG is left behind") {
  create_output_directory(dir_, "sinks.png.dir");
  remove_stale_temporaries(dir_, [](std::string_view target) { return target.starts_with("frame_"); });
}

PngSink::~PngSink() { outage_.report_at_end(); }

std::string PngSink::describe() const { return "png:" + dir_.string(); }

std::filesystem::path PngSink::file_name(const std::filesystem::path& dir, uint64_t index) {
  return dir / fmt::format("frame_{:06d}.png", index);
}

void PngSink::consume(const FrameContext& ctx) noexcept {
  if (ctx.output.empty() || ctx.input_index % uint64_t(every_) != 0) return;
  std::string why;
  try {
    const auto path = file_name(dir_, ctx.input_index);
    const cv::Mat rgb(ctx.output.height, ctx.output.width, CV_8UC3, const_cast<uint8_t*>(ctx.output.data.data()),
                      ctx.output.bytes_per_line);
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    // Encoded in memory: libpng never meets a failing file (and prints nothing), and the file is
    // written whole or not at all.
    std::vector<uint8_t> png;
    // Level 1 is OpenCV's default, which also picks its fast filter and strategy: naming the level
    // would switch those, so the default stays unnamed and its PNGs keep their bytes.
    std::vector<int> params;
    if (compression_ != 1) params = {cv::IMWRITE_PNG_COMPRESSION, compression_};
    if (!cv::imencode(".png", bgr, png, params)) throw std::runtime_error("the PNG encoder refused the frame");
    if (const int error = replace_file(path, png))
      why = fmt::format("{}: {}", path.string(), std::strerror(error));
  } catch (const std::exception& e) {
    why = e.what();
  }
  if (why.empty()) outage_.succeeded(ctx.input_index);
  else outage_.failed(ctx.input_index, why);
}

}  // namespace arpipe
