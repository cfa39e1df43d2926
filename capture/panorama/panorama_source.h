// source.type = "panorama": frames of a 360° still seen through the view camera as it turns
// (source.panorama.view), each with the pose it was seen from (FrameMetadata::known_T_cam_world),
// so the virtual objects and proxies are drawn from exactly where the background was looked up.
#pragma once

#include <memory>

#include "core/config/config.h"
#include "core/pipeline/frame_source.h"

namespace arpipe {

class PanoramaSource : public FrameSource {
 public:
  // Loads the panorama and the view's lens. Throws AssetError (the panorama file), CameraModelError
  // (the view's model) or ConfigError. carries_light (light.source = "panorama"): every frame also
  // carries the panorama's light (FrameMetadata::environment_sh, capture/panorama/panorama_light.h),
  // a still's from every texel at setup, a video's from each frame shown.
  explicit PanoramaSource(const SourceConfig& config, bool carries_light = false);
  ~PanoramaSource() override;

  std::string describe() const override;
  bool is_live() const override { return false; }
  std::shared_ptr<const CameraModel> camera_model() const override;
  std::optional<int64_t> frame_interval_ns() const override;
  // Frame k (RGB24) shows the view at time k / fps: exposure_start_ns = k / fps in ns, exposure 0
  // (a still has no motion blur), sequence k. Paced at fps with source.pacing = "timestamps".
  // Ends after view.frames frames (never with 0).
  SourceStatus next(Frame& frame) override;
  void interrupt() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The view camera's pose turned by R_pano_cam (the view's axes in the panorama's frame): its centre at
// position_m, in the panorama placed by its yaw about world z.
SE3 panorama_view_pose(const PanoramaConfig& config, const Mat3& R_pano_cam);
// The sweep's turn at time t_s (the view's yaw plus yaw_rad_per_s * t_s, and its pitch), without a track.
Mat3 panorama_view_rotation_at(const PanoramaConfig& config, double t_s);

}  // namespace arpipe
