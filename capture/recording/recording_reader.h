// Reads a recording directory (format v1). A recording cut off mid-frame opens with a warning and
// yields its complete frames; anything else malformed is a RecordingError naming file and place.
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
  explicit RecordingReader(const std::filesystem::path& dir);  // throws RecordingError
  ~RecordingReader();

  const RecordingInfo& info() const;
  const CameraModel& camera_model() const;
  size_t frame_count() const;
  // Frame i with its metadata. Throws RecordingError if its pixels fail their checksum.
  void read(size_t index, Frame& frame) const;
  const FrameMetadata& metadata(size_t index) const;
  // Ground truth per frame, empty when the recording has none.
  const std::vector<GroundTruthFrame>& ground_truth() const;
  // Warnings found while opening (truncated tail, ...), for the caller to log.
  const std::vector<std::string>& warnings() const;
  const std::filesystem::path& dir() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
