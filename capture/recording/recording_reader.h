// Reads a recording directory (format v1). A recording cut off at any byte opens with a warning
// and yields its complete frames; anything else malformed is a RecordingError naming file and place.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "capture/recording/recording_format.h"
#include "core/frame.h"
#include "core/geometry/camera_model.h"

namespace arpipe {

class RecordingReader {
 public:
  // Reads recording.json, the camera model and all per-frame metadata (payloads are read on
  // demand). Throws RecordingError; logs each warning through arpipe::log as well.
  explicit RecordingReader(const std::filesystem::path& dir);
  ~RecordingReader();

  const RecordingInfo& info() const;
  const CameraModel& camera_model() const;
  size_t frame_count() const;
  // Frame i with its metadata. Throws RecordingError naming the frame and its byte offset if its
  // pixels fail their checksum or cannot be read. Safe to call from several threads.
  void read(size_t index, Frame& frame) const;
  const FrameMetadata& metadata(size_t index) const;
  // Ground truth per frame: empty when the recording has none, else entry i belongs to frame i.
  const std::vector<GroundTruthFrame>& ground_truth() const;
  // Warnings found while opening (cut-off tail, ...).
  const std::vector<std::string>& warnings() const;
  const std::filesystem::path& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
