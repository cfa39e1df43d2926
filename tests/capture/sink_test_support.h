// Helpers for the sink failure tests: frame contexts with a known picture, a file size limit that
// stands in for a full disk (RLIMIT_FSIZE: writes past it fail with EFBIG), and log counting.
#pragma once

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/pipeline/frame_context.h"

namespace arpipe::test {

// A context whose composited output is an RGB24 picture of pseudo-random bytes seeded by index
// (frames differ, and their PNGs hardly compress: about width*height*3 bytes).
inline FrameContext sink_context(int width, int height, uint64_t index) {
  FrameContext ctx;
  ctx.input_index = index;
  ctx.camera.meta.sequence = 1000 + index;
  ctx.camera.meta.exposure_start_ns = 2'000'000'000 + int64_t(index) * 40'000'000;
  ctx.camera.meta.frame_duration_ns = 40'000'000;
  ctx.output.format = PixelFormat::RGB24;
  ctx.output.width = width;
  ctx.output.height = height;
  ctx.output.bytes_per_line = size_t(width) * 3;
  ctx.output.data.resize(ctx.output.bytes_per_line * size_t(height));
  uint64_t state = 0x9E3779B97F4A7C15ull * (index + 1);
  for (auto& byte : ctx.output.data) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;  // Knuth's MMIX LCG
    byte = uint8_t(state >> 56);
  }
  ctx.output.meta = ctx.camera.meta;
  return ctx;
}

// While alive, no file of this process may grow past `bytes` (writes past it fail with EFBIG, a
// write across it is cut short), as on a disk that has just filled up.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(uint64_t bytes) {
    EXPECT_EQ(getrlimit(RLIMIT_FSIZE, &saved_), 0);
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
    rlimit limited = saved_;
    limited.rlim_cur = bytes;
    EXPECT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, previous_handler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  rlimit saved_{};
  void (*previous_handler_)(int) = SIG_DFL;
};

// A Y4M stream as the sink writes it: the header line, then "FRAME\n" + width*height*3/2 bytes each.
struct Y4mStream {
  std::string header;                          // with its newline
  std::vector<std::string> frames;             // I420 payloads of the complete frames
  size_t torn_tail_bytes = 0;                  // bytes after the last complete frame
  bool markers_ok = true;                      // every frame starts with "FRAME\n"
};

inline Y4mStream parse_y4m_stream(const std::string& bytes, int width, int height) {
  Y4mStream out;
  const size_t header_end = bytes.find('\n');
  if (header_end == std::string::npos) {
    out.torn_tail_bytes = bytes.size();
    return out;
  }
  out.header = bytes.substr(0, header_end + 1);
  const size_t payload = size_t(width) * size_t(height) * 3 / 2;
  size_t at = header_end + 1;
  for (; at + 6 + payload <= bytes.size(); at += 6 + payload) {
    if (bytes.compare(at, 6, "FRAME\n") != 0) out.markers_ok = false;
    out.frames.push_back(bytes.substr(at + 6, payload));
  }
  out.torn_tail_bytes = bytes.size() - at;
  return out;
}

// How often `needle` occurs in `text`.
inline size_t occurrences(std::string_view text, std::string_view needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string_view::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// The names in a directory, sorted.
inline std::vector<std::string> directory_names(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace arpipe::test
