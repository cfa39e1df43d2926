#include "capture/sinks/png_sink.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "capture/sinks/output_path.h"
#include "capture/sinks/png_encoding.h"

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
    // Encoded in memory: libpng never meets a failing file (and prints nothing), and the file is
    // written whole or not at all.
    const std::vector<uint8_t> png = encode_png(ctx.output, compression_);
    if (const int error = replace_file(path, png))
      why = fmt::format("{}: {}", path.string(), std::strerror(error));
  } catch (const std::exception& e) {
    why = e.what();
  }
  if (why.empty()) outage_.succeeded(ctx.input_index);
  else outage_.failed(ctx.input_index, why);
}

}  // namespace arpipe
