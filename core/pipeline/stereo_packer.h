// A stereo panorama's two eyes as one output frame (source.panorama.view.stereo_output): the
// source gives each time step the left eye's frame, then the right eye's (FrameMetadata::eye);
// the sinks see one frame a time step with both pictures, the left eye's on top or on the left,
// as stereo 360 players and headsets take them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/config/panorama_config.h"
#include "core/pipeline/frame_context.h"

namespace arpipe {

class StereoPacker {
 public:
  explicit StereoPacker(StereoOutput packing) : packing_(packing) {}

  // A mono frame comes back as it is. A left eye's is held (nothing comes back); the right eye's
  // of the same time step comes back packed with it: the left's context (its pose, objects and
  // timings; the right's timings added with " (right eye)" after their stage's name) with the two
  // composited pictures side by side or one above the other in `output` (and so the camera
  // frames, for RGB24 sources), meta.eye = Eye::Pair. A right eye without its left, or a left
  // followed by anything but its right, is dropped and counted.
  std::optional<FrameContext> add(FrameContext ctx);
  uint64_t unpaired() const { return unpaired_; }

 private:
  // The pictures' lens: the eye's over the whole pair (exact for the left half, which starts at
  // the top left corner), so that a recording of the pairs carries a model of their size.
  std::shared_ptr<const CameraModel> lens_over_pair(const std::shared_ptr<const CameraModel>& eye, const Frame& pair);
  struct PairLens {
    std::shared_ptr<const CameraModel> eye, over;
  };
  std::vector<PairLens> lenses_;  // the few made so far (the output's and the camera's)

  StereoOutput packing_;
  std::optional<FrameContext> left_;
  uint64_t unpaired_ = 0;
};

// The two pictures in one: `right` below or to the right of `left` (the same format and size),
// or an empty frame when they differ.
Frame pack_stereo_pair(const Frame& left, const Frame& right, StereoOutput packing);

}  // namespace arpipe
