// Recording format v1 (docs/FORMATS.md): a self-describing, versioned directory with per-frame
// metadata as text, frames in the camera's own pixel format, the camera model, optional ground truth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/geometry/se3.h"
#include "core/pixel_format.h"

namespace arpipe {

inline constexpr const char* kRecordingFormatName = "arpipe-recording";
inline constexpr int kRecordingFormatVersion = 1;

// The file names a writer gives the parts; readers take the names from recording.json's "files".
inline constexpr const char* kRecordingInfoFile = "recording.json";
inline constexpr const char* kRecordingCameraModelFile = "camera.cameramodel";
inline constexpr const char* kRecordingFramesFile = "frames.bin";
inline constexpr const char* kRecordingMetadataFile = "frames.jsonl";
inline constexpr const char* kRecordingGroundTruthFile = "ground_truth.jsonl";

// Bad recording input; what() names the file, the line or byte offset, and what was expected.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// recording.json: what every frame of the recording shares.
struct RecordingInfo {
  int version = kRecordingFormatVersion;
  PixelFormat pixel_format = PixelFormat::RGB24;
  int width = 0;
  int height = 0;
  size_t bytes_per_line = 0;  // 0 when writing: the minimum for the format and width
  std::string source;         // free text: "arpipe generate ...", "v4l2:/dev/video0", ...
  std::string created_utc;    // ISO 8601, "2024-05-01T12:00:00Z"; empty when writing: now
};

// Ground truth of a simulated frame (ground_truth.jsonl), world = anchor frame.
struct GroundTruthFrame {
  uint64_t sequence = 0;
  SE3 T_cam_world_start;  // at exposure start of the first row
  SE3 T_cam_world_mid;    // at the middle of the exposure (FrameMetadata::exposure_mid_ns)
  SE3 T_cam_world_end;    // at exposure end of the last row
};

}  // namespace arpipe
