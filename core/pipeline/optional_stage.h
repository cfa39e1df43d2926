// A stage that runs only while the config asks for it (the light stage for any light source but the
// fixed one, the motion stage while tracking and motion are on), so that a reload can add or remove
// it. Switched off it does nothing at all, not even record a timing: as if it were not in the list.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "core/pipeline/stage.h"

namespace arpipe {

class OptionalStage final : public Stage {
 public:
  using Wanted = std::function<bool(const Config&)>;
  using Make = std::function<std::unique_ptr<Stage>()>;
  OptionalStage(Wanted wanted, Make make);

  std::string_view name() const override { return name_; }
  void configure(const Config& config) override { configure_loaded(config, nullptr); }
  // The stage's own loader, for configs that want the stage; nothing is loaded for the others.
  StageAssetLoader asset_loader() const override;
  // Switched on: configures the stage (a fresh one when frames went by without it: its state from
  // before is stale). Switched off: keeps it aside, so that a reload refused by a later stage can
  // put it back as it was. Throws as the stage does, and then stays as it was.
  void configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) override;
  void prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept override;
  void process(FrameContext& ctx) noexcept override;
  int latency_frames() const noexcept override;
  void look_ahead(const FrameContext& next) noexcept override;

  bool running() const { return on_; }

 private:
  Wanted wanted_;
  Make make_;
  std::unique_ptr<Stage> stage_;
  std::string name_;
  StageAssetLoader loader_;  // the stage's, taken once (it holds no reference to the stage)
  bool on_ = false;
  bool stale_ = false;  // frames went by while off
};

}  // namespace arpipe
