// The coverage recording's pixels: 8-bit GREY, round(coverage x 255) (see ground_truth_coverage.h).
#include "capture/sim/ground_truth_coverage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "capture/recording/recording_reader.h"

namespace arpipe::sim {

namespace fs = std::filesystem;

uint8_t coverage_to_byte(double coverage) {
  if (!(coverage > 0)) return 0;  // NaN too
  return uint8_t(std::lround(std::min(coverage, 1.0) * 255.0));
}

float coverage_from_byte(uint8_t byte) { return float(byte) / 255.0f; }

Frame coverage_frame(const std::vector<float>& coverage, int width, int height, const FrameMetadata& meta) {
  Frame frame = Frame::allocate(PixelFormat::GREY, width, height);
  frame.meta = meta;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      frame.data[size_t(y) * frame.bytes_per_line + size_t(x)] =
          coverage_to_byte(coverage[size_t(y) * size_t(width) + size_t(x)]);
  return frame;
}

namespace {

fs::path coverage_dir(const fs::path& capture_dir) {
  const fs::path dir = capture_dir / kGroundTruthCoverageDir;
  if (!fs::is_directory(dir))
    throw RecordingError(fmt::format("{}: no ground-truth coverage (simulated captures with virtual objects have one)",
                                     dir.string()));
  return dir;
}

void check_grey(const RecordingReader& reader) {
  if (reader.info().pixel_format != PixelFormat::GREY)
    throw RecordingError(fmt::format("{}: expected a GREY coverage recording, found {}", reader.dir().string(),
                                     pixel_format_name(reader.info().pixel_format)));
}

}  // namespace

size_t coverage_frame_count(const fs::path& capture_dir) {
  const RecordingReader reader(coverage_dir(capture_dir));
  check_grey(reader);
  return reader.frame_count();
}

CoverageImage read_coverage_frame(const fs::path& capture_dir, size_t index) {
  const RecordingReader reader(coverage_dir(capture_dir));
  check_grey(reader);
  if (index >= reader.frame_count())
    throw RecordingError(
        fmt::format("{}: no coverage frame {} (it has {})", reader.dir().string(), index, reader.frame_count()));
  Frame frame;
  reader.read(index, frame);
  CoverageImage out;
  out.width = frame.width;
  out.height = frame.height;
  out.coverage.resize(size_t(frame.width) * size_t(frame.height));
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x)
      out.coverage[size_t(y) * size_t(frame.width) + size_t(x)] =
          coverage_from_byte(frame.data[size_t(y) * frame.bytes_per_line + size_t(x)]);
  return out;
}

}  // namespace arpipe::sim
