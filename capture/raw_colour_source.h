// Decides how each raw Bayer frame develops before any stage sees it (core/raw_colour.h), so the
// tracker, the light stage, the composite and the sinks all see the same colours: [source.raw]
// over what the camera said, and grey-world gains measured once per frame when none are known.
// Frames of other formats pass untouched.
#pragma once

#include <memory>
#include <string>

#include "core/config/raw_colour_config.h"
#include "core/frame.h"
#include "core/pipeline/frame_source.h"

namespace arpipe {

class RawColourResolver {
 public:
  explicit RawColourResolver(RawColourConfig config) : config_(std::move(config)) {}

  // Sets a Bayer frame's meta.raw, gains included. Never throws. What the camera said that cannot
  // develop the frame (a black level at or above its white level, a gain that is not positive) is
  // dropped, and a [source.raw] value that cannot apply to the frame's bit depth is not applied:
  // each logged once, naming the value.
  void resolve(Frame& frame);

 private:
  RawColourConfig config_;
  bool reported_camera_problem_ = false;
  bool reported_config_problem_ = false;
  bool described_ = false;
};

// A source whose Bayer frames leave it resolved by RawColourResolver.
class RawColourSource final : public FrameSource {
 public:
  RawColourSource(std::unique_ptr<FrameSource> inner, RawColourConfig config)
      : inner_(std::move(inner)), resolver_(std::move(config)) {}

  std::string describe() const override { return inner_->describe(); }
  bool is_live() const override { return inner_->is_live(); }
  std::shared_ptr<const CameraModel> camera_model() const override { return inner_->camera_model(); }
  std::optional<int64_t> frame_interval_ns() const override { return inner_->frame_interval_ns(); }
  SourceStatus next(Frame& frame) override;
  void interrupt() override { inner_->interrupt(); }
  std::string health() const override { return inner_->health(); }
  bool connected() const override { return inner_->connected(); }
  std::optional<CaptureCounts> capture_counts() const override { return inner_->capture_counts(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  RawColourResolver resolver_;
};

}  // namespace arpipe
