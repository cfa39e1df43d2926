// Appends frames to a recording directory, crash-safely: a frame's pixels are written before its
// metadata line, so a recording cut off at any byte replays up to its last complete frame.
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
  // Creates the directory (which must not hold a recording already) and writes recording.json and
  // camera.cameramodel. Throws RecordingError naming the path.
  RecordingWriter(const std::filesystem::path& dir, const RecordingInfo& info, const CameraModel& model);
  ~RecordingWriter();

  // Appends one frame (its format and size must match the info). Throws RecordingError on I/O
  // failure; what was appended before stays readable.
  void append(const Frame& frame, const std::optional<GroundTruthFrame>& truth = std::nullopt);
  // fsync()s data and metadata so far.
  void flush();
  uint64_t frames_written() const;
  const std::filesystem::path& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
