// A stage that runs only while the config asks for it (see optional_stage.h).
#include "core/pipeline/optional_stage.h"

namespace arpipe {

OptionalStage::OptionalStage(Wanted wanted, Make make)
    : wanted_(std::move(wanted)), make_(std::move(make)), stage_(make_()), name_(stage_->name()),
      loader_(stage_->asset_loader()) {}

StageAssetLoader OptionalStage::asset_loader() const {
  if (!loader_) return {};
  return [wanted = wanted_, loader = loader_](const Config& config) -> std::shared_ptr<const StageAssets> {
    return wanted(config) ? loader(config) : nullptr;
  };
}

void OptionalStage::configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) {
  if (!wanted_(config)) {
    on_ = false;
    return;
  }
  if (!on_ && stale_) {
    std::unique_ptr<Stage> fresh = make_();
    fresh->configure_loaded(config, assets);
    stage_ = std::move(fresh);
    stale_ = false;
  } else {
    stage_->configure_loaded(config, assets);
  }
  on_ = true;
}

void OptionalStage::prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept {
  if (on_) stage_->prepare(camera_model);
}

void OptionalStage::process(FrameContext& ctx) noexcept {
  if (on_)
    stage_->process(ctx);
  else
    stale_ = true;
}

int OptionalStage::latency_frames() const noexcept { return on_ ? stage_->latency_frames() : 0; }

void OptionalStage::look_ahead(const FrameContext& next) noexcept {
  if (on_) stage_->look_ahead(next);
}

}  // namespace arpipe
