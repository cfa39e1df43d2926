// Renders one simulated frame's radiance: per pixel, stratified samples over the pixel's area and
// over its own row's exposure window (motion blur and rolling shutter), shaded by a SceneShader.
#pragma once

#include <cstdint>
#include <vector>

#include "capture/sim/camera_ray_grid.h"
#include "capture/sim/scene_shader.h"
#include "capture/sim/shutter_pose_table.h"
#include "core/frame.h"

namespace arpipe::sim {

// Mean linear radiance per pixel, RGB interleaved, row-major.
struct RadianceImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
};

// Random-number streams of one pixel of one frame: independent per purpose, so the sensor noise
// of a pixel is the same whichever shader (with or without virtual objects) lit it.
enum class SampleStream : uint64_t { Shading = 0, SensorNoise = 1 };
uint64_t sample_stream(uint64_t frame_index, uint64_t pixel_index, SampleStream purpose);

class FrameRenderer {
 public:
  // samples_per_pixel must be a square; threads: 0 for one per core.
  FrameRenderer(const CameraRayGrid& rays, int width, int height, int samples_per_pixel, uint64_t seed, int threads = 0);

  // poses: the camera over this frame's exposure window; trajectory_time_s: the trajectory's time
  // at meta.exposure_start_ns. coverage, when given, receives per pixel (row-major) the fraction
  // of the pixel's samples whose first hit is a virtual object (the same samples as `out`; a
  // sample outside what the lens sees counts as not covered).
  // eye: an omnidirectional-stereo pair's eye (Eye::Mono: every ray from the camera's centre):
  // each ray leaves ods_eye_origin(rig, eye, the camera's up, its direction), and the right eye's
  // pixels draw their own random numbers (as the pixels of a frame below the left eye's).
  void render(const SceneShader& shader, const ShutterPoseTable& poses, const FrameMetadata& meta,
              double trajectory_time_s, uint64_t frame_index, RadianceImage& out,
              std::vector<float>* coverage = nullptr, Eye eye = Eye::Mono, const OdsRig& rig = {}) const;

 private:
  const CameraRayGrid& rays_;
  int width_;
  int height_;
  int samples_per_pixel_;
  int samples_per_axis_;
  uint64_t seed_;
  int threads_;
};

}  // namespace arpipe::sim
