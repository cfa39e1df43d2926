// The motion stage: the camera's pose at exposure start and end (and per row) of each frame, from
// the tracked poses of nearby frames and the frame's exposure metadata (docs/ARCHITECTURE.md).
#pragma once

#include <memory>
#include <vector>

#include "core/pipeline/stage.h"

namespace arpipe {

class MotionStage : public Stage {
 public:
  MotionStage();
  ~MotionStage() override;
  std::string_view name() const override { return "motion"; }
  // Throws ConfigError on motion values the config reader would refuse (a Config built in code).
  void configure(const Config& config) override;
  // Fills ctx.motion from ctx.pose (after the track stage). A frame without a pose gets
  // state None with the reason, and the stage records it as its skip reason.
  void process(FrameContext& ctx) noexcept override;

  // latency_frames = 1: the runner shows the stage frame n+1 (after tracking it) before calling
  // process() on frame n, so that n's exposure end is interpolated instead of extrapolated
  // (Stage::latency_frames). Where n+1 has no pose (the end of the stream, tracking lost), n's end
  // is extrapolated (state Extrapolated).
  void look_ahead(const FrameContext& next) noexcept override;
  int latency_frames() const noexcept override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The time a tracked pose belongs to: the middle of the exposure of the rows the bundle's tags lie
// on (the mean row of their corners), which for a global shutter is the middle of the exposure.
// Without corners of a bundle tag, the middle row's (FrameMetadata::exposure_mid_ns).
int64_t tracked_pose_time_ns(const ShutterTiming& timing, const PoseEstimate& pose, const std::vector<BundleTag>& bundle);

}  // namespace arpipe
