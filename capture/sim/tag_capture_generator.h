// A simple capture generator (until the full simulator): a camera moving over a printed AprilTag,
// rendered by inverse-mapping every pixel through the camera model onto the tag plane, with
// exact ground-truth poses. Writes a format-v1 recording.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "capture/recording/recording_format.h"
#include "core/geometry/camera_model.h"
#include "core/pixel_format.h"

namespace arpipe {

struct TagCaptureOptions {
  int width = 640;
  int height = 480;
  std::string lensmodel = "LENSMODEL_OPENCV4";  // PINHOLE or OPENCV4/5/8; mild distortion exercises the lens path
  int frames = 60;
  double fps = 30.0;
  int64_t exposure_ns = 4'000'000;
  PixelFormat pixel_format = PixelFormat::YUYV;
  std::string family = "tag36h11";
  int tag_id = 0;
  double tag_size_m = 0.1;   // black-border edge, as AprilTag measures it
  uint64_t seed = 1;         // noise seed
  double noise_sigma = 1.0;  // 8-bit units
  int look_away_frames = 3;  // the last frames look away from the tag (tracking lost); 0: none
};

// Generates the recording into dir (which must not hold a recording). Returns the number of frames
// written. Throws std::invalid_argument on bad options, RecordingError when writing fails.
int generate_tag_capture(const std::filesystem::path& dir, const TagCaptureOptions& options);

// What generate_tag_capture uses, for tests and tools that want the truth without rendering.
CameraModel tag_capture_camera_model(const TagCaptureOptions& options);
std::vector<GroundTruthFrame> tag_capture_ground_truth(const TagCaptureOptions& options);

}  // namespace arpipe
