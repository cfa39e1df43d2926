// Replays a recording in place of a live camera: paced by the frames' timestamps or as fast as
// possible, optionally looping. Never drops frames (the pipeline blocks instead).
#pragma once

#include <memory>

#include "core/config/config.h"
#include "core/pipeline/frame_source.h"

namespace arpipe {

class ReplaySource : public FrameSource {
 public:
  // Opens the recording named by config.path; throws RecordingError / CameraModelError on bad input
  // (including a camera_model override whose image size differs from the recording's).
  explicit ReplaySource(const SourceConfig& config);
  ~ReplaySource() override;

  std::string describe() const override;
  bool is_live() const override { return false; }
  std::shared_ptr<const CameraModel> camera_model() const override;
  SourceStatus next(Frame& frame) override;
  void interrupt() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arpipe
