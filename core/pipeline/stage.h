// A processing stage: configured once, then called per frame on the processing thread.
// process() never throws: a problem with one frame is recorded in the FrameContext.
#pragma once

#include <functional>
#include <memory>
#include <string_view>

#include "core/config/config.h"
#include "core/pipeline/frame_context.h"

namespace arpipe {

// What a stage loads for one config away from the processing thread (meshes, baked transfers,
// decoded images): opaque to the runner, which only carries it from the loader to configure_loaded().
struct StageAssets {
  virtual ~StageAssets() = default;
};
using StageAssetLoader = std::function<std::shared_ptr<const StageAssets>(const Config&)>;

class Stage {
 public:
  virtual ~Stage() = default;
  virtual std::string_view name() const = 0;
  // Called before the first frame and again on a config reload. May throw ConfigError (or any
  // std::exception) to refuse the config; the stage then keeps its previous configuration.
  virtual void configure(const Config& config) = 0;
  // The slow part of configuring that needs no GL context: reading, decoding, baking. On a reload
  // the runner calls the returned function on the reloading thread, never on the processing thread,
  // so frames keep flowing while it runs; it may throw to refuse the config. It must hold no
  // reference to the stage (a load stuck on a file may outlive it) and must not touch the running
  // configuration. Empty (the default) when configure() has nothing slow to do.
  virtual StageAssetLoader asset_loader() const { return {}; }
  // configure() with what asset_loader() made of this same config (null when the stage has no
  // loader): how the runner configures, on the processing thread. Same contract as configure().
  virtual void configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) {
    (void)assets;
    configure(config);
  }
  // Called after each configure, before the next frame, with the source's camera model (null when
  // it has none): the place to build what depends on the lens (a warp map takes a few hundred ms),
  // so that the first frames do not stall. Must not throw: a lens the stage cannot use shows up on
  // the frames, as it would without this call.
  virtual void prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept { (void)camera_model; }
  // Per frame. Must not throw. Records its own timing (and skip reason) in ctx.
  virtual void process(FrameContext& ctx) noexcept = 0;
  // How many later frames this stage wants to have seen before it processes a frame (the motion
  // stage interpolates a frame's exposure end towards the next frame's pose). The runner then holds
  // each frame back after the stages before this one and shows the stage each arriving frame
  // through look_ahead() first; at the end of the stream the held frames go on without.
  virtual int latency_frames() const noexcept { return 0; }
  // Whether process() reads and writes only the frame it is given and the stage's own state, so
  // that as the first stage it may process frame n + 1 on another thread while the later stages
  // process frame n (pipeline.overlap_first_stage).
  virtual bool can_run_ahead() const noexcept { return false; }
  // Work on a frame that reads only its camera image and what configure() set, never what this
  // stage does to earlier frames, and writes only its own fields of the frame (converting the camera
  // picture): when the first stage runs ahead, the runner has it done by whichever thread is free
  // first, the helper after the first stage or the processing thread after the frame before, so it
  // may run beside this stage's process() of the frame before and the first stage's of this one.
  // Only then; process() must do whatever it finds not done. Must not throw.
  virtual void process_ahead(FrameContext& ctx) noexcept { (void)ctx; }
  virtual void look_ahead(const FrameContext& next) noexcept { (void)next; }
};

}  // namespace arpipe
