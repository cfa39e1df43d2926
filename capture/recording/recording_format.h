// Recording format v1 (docs/FORMATS.md): a self-describing, versioned directory with per-frame
// metadata as text, frames in the camera's own pixel format, the camera model, optional ground truth.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

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
  std::string source;         // free text: "arpipe simulate ...", "v4l2:/dev/video0", ...
  std::string created_utc;    // ISO 8601, "2024-05-01T12:00:00Z"; empty when writing: now
};

// The pose of one row of a rolling-shutter frame at the middle of that row's exposure.
struct GroundTruthRowPose {
  int row = 0;
  SE3 T_cam_world;
};

// A light of the simulated scene in the world frame (docs/FORMATS.md "ground_truth.jsonl").
struct GroundTruthLight {
  std::string name;
  std::string kind;  // "directional", "point" or "sphere"
  Vec3 direction_to_light{0, 0, 0};  // directional: unit vector towards the light
  Vec3 position{0, 0, 0};            // point, sphere
  std::array<double, 3> color{1, 1, 1};
  double strength = 0;  // directional: irradiance (W/m^2); point, sphere: intensity (W/sr)
  double angular_diameter_rad = 0;  // directional
  double radius_m = 0;              // sphere
  bool operator==(const GroundTruthLight&) const = default;
};

struct GroundTruthSun {
  double azimuth_rad = 0;  // east of true north
  double elevation_rad = 0;
  bool operator==(const GroundTruthSun&) const = default;
};

// Ground truth of a simulated frame (ground_truth.jsonl), world = anchor frame.
struct GroundTruthFrame {
  uint64_t sequence = 0;
  SE3 T_cam_world_start;  // at exposure start of the first row
  SE3 T_cam_world_mid;    // at the middle of the exposure (FrameMetadata::exposure_mid_ns)
  SE3 T_cam_world_end;    // at exposure end of the last row
  // What the simulator knows beyond the poses; empty/absent in files from older writers.
  std::vector<GroundTruthRowPose> rows;  // rolling shutter: a sample of rows, the first and last included
  std::vector<GroundTruthLight> lights;
  std::optional<GroundTruthSun> sun;
  int64_t exposure_ns = 0;  // what the sensor really used (0: not recorded)
  double analogue_gain = 0;
  double digital_gain = 0;
  std::string linear_image;  // file name (relative to the recording) of the noise-free linear image
};

}  // namespace arpipe
