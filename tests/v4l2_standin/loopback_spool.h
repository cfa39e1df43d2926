// The spool directory through which a loopback's output node hands frames to its capture node, in
// this process or another: a `format` file and one file per frame, each made whole before it appears.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/pixel_format.h"

namespace arpipe::standin {

// The largest width and height a spool file may declare (the config's max_width/max_height range).
inline constexpr uint32_t kMaxSpoolDimension = 16384;

// What the writer negotiated: pixel format, size, layout and frame interval.
struct SpoolFormat {
  PixelFormat format = PixelFormat::YUYV;
  uint32_t width = 0, height = 0, bytes_per_line = 0, size_image = 0;
  uint32_t interval_num = 1, interval_den = 30;  // seconds per frame, as V4L2's timeperframe

  bool operator==(const SpoolFormat&) const = default;
};

// One written frame.
struct SpoolFrame {
  SpoolFormat format;
  uint32_t bytes_used = 0;
  uint32_t sequence = 0;         // the writer's, since its STREAMON
  int64_t timestamp_ns = 0;      // CLOCK_MONOTONIC (whole microseconds: it came in a timeval)
  bool timestamp_copied = false; // the writer gave it (V4L2_BUF_FLAG_TIMESTAMP_COPY); else the time it was written
};

// The layout a pixel format and size take with the minimum stride.
SpoolFormat spool_format(PixelFormat format, uint32_t width, uint32_t height);

class SpoolWriter {
 public:
  SpoolWriter(std::filesystem::path dir, int64_t max_bytes) : dir_(std::move(dir)), max_bytes_(max_bytes) {}
  // Replaces the `format` file; "" or why it failed.
  std::string write_format(const SpoolFormat& format);
  // Appends a frame after the newest one in the directory (written by any process); "" or why
  // not (the spool would pass max_bytes, or the write failed). The file appears whole or not at all.
  std::string append(const SpoolFrame& frame, const uint8_t* bytes);
  // Another writer may have added frames: the next append looks at the directory again.
  void rescan() { next_index_.reset(); }

 private:
  std::filesystem::path dir_;
  int64_t max_bytes_;
  std::optional<uint64_t> next_index_;
  int64_t bytes_ = 0;  // frame files in the directory, at the last look plus what this writer added
};

class SpoolReader {
 public:
  explicit SpoolReader(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // The writer's current format; nullopt when none has been written (error empty) or the file is
  // bad (error says where and why).
  std::optional<SpoolFormat> read_format(std::string& error) const;
  // The oldest frame's index in the directory (0 when there is none).
  uint64_t first_index() const;
  enum class Result { Absent, Bad, Ok };
  // Reads frame `index` into dst (capacity bytes). Bad: the file breaks the format, or does not
  // fit; error names the file and what was expected.
  Result read_frame(uint64_t index, SpoolFrame& frame, uint8_t* dst, size_t capacity, std::string& error) const;
  std::filesystem::path frame_path(uint64_t index) const;

 private:
  std::filesystem::path dir_;
};

}  // namespace arpipe::standin
