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
  // (a still has no motion blur), sequence k, the viewpoint shown (FrameMetadata::viewpoint; with
  // several, each for view.dwell_s in turn). Paced at fps with source.pacing = "timestamps".
  // Ends after view.frames frames (never with 0). A stereo layout gives two frames a time step, the
  // left eye's (sequence 2k) then the right eye's (2k + 1), with the same times and pose
  // (FrameMetadata::eye); view.frames counts time steps.
  SourceStatus next(Frame& frame) override;
  void interrupt() override;
  // "video frames skipped N (undecodable or of another size), frames failed M" once either is not
  // 0 (a frame fails when its video cannot be read back from the start); empty before.
  std::string health() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The view camera's pose turned by R_pano_cam (the view's axes in the panorama's frame): its centre
// at the viewpoint's position_m, in its panorama placed by its yaw about world z.
SE3 panorama_view_pose(const PanoramaViewpoint& viewpoint, const Mat3& R_pano_cam);
// The sweep's turn t_s after arriving at a viewpoint (the view's yaw plus yaw_rad_per_s * t_s, and
// its pitch), without a track.
Mat3 panorama_view_rotation_at(const PanoramaConfig& config, double t_s);

// Where the view is at output time t_ns (>= 0): viewpoint (t / dwell) mod their count, arrived at
// the last multiple of dwell_s; viewpoint 0 from 0 throughout with one viewpoint.
struct PanoramaStop {
  size_t viewpoint = 0;
  int64_t arrived_ns = 0;
};
PanoramaStop panorama_stop_at(const PanoramaConfig& config, int64_t t_ns);

}  // namespace arpipe
