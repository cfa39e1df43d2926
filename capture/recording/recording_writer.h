// Appends frames to a recording directory, crash-safely: a frame's pixels (and ground truth) are
// written before its metadata line, so a recording cut off at any byte replays up to its last complete frame.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>

#include "capture/recording/recording_format.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"

namespace arpipe {

class RecordingWriter {
 public:
  // Creates the directory (parents included; it must not hold a recording already) and writes
  // camera.cameramodel, the empty frame files and recording.json (created_utc and bytes_per_line
  // filled in when empty/0). Throws RecordingError naming the path.
  RecordingWriter(const std::filesystem::path& dir, const RecordingInfo& info, const CameraModel& model);
  ~RecordingWriter();  // flushes (errors are logged)

  // Appends one frame (its format, size and stride must match the info). Ground truth is given for
  // every frame of a recording or for none. Throws RecordingError on bad input or I/O failure;
  // what was appended before stays readable, and a later append may retry.
  void append(const Frame& frame, const std::optional<GroundTruthFrame>& truth = std::nullopt);
  // fsync()s data and metadata so far.
  void flush();
  uint64_t frames_written() const;
  const RecordingInfo& info() const;
  const std::filesystem::path& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
