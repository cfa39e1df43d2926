// The track stage: AprilTag detection and the camera pose relative to the anchor (a tag or a bundle).
// World frame = anchor: x along the tag's right edge, y along its top edge, z out of its face.
#pragma once

#include <memory>

#include "core/pipeline/stage.h"

namespace arpipe {

class TagTracker : public Stage {
 public:
  TagTracker();
  ~TagTracker() override;
  std::string_view name() const override { return "track"; }
  void configure(const Config& config) override;
  // Fills ctx.pose from ctx.camera and ctx.camera_model. Lost tracking is a state, never an error.
  void process(FrameContext& ctx) noexcept override;
  // It needs only the frame, the camera model it carries and its own pose history. Not with nothing
  // virtual to draw: then it tracks nothing, and running ahead would only hand the frame over.
  bool can_run_ahead() const noexcept override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
