// The light stage: where this frame's light comes from (light.source): the config's fixed light,
// a light probe sphere in view (probe_light_estimator.h), the sun from place and time
// (sun_light.h), an HDR light probe file (environment_light.h), or the panorama source's image
// (capture/panorama/panorama_light.h, arriving with each frame). Its estimate travels in
// FrameContext::light to the renderer.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/config/light_source.h"
#include "core/light/ground_radiance.h"
#include "core/light/light_hold.h"
#include "core/probe/probe_light_estimator.h"
#include "core/scene/gltf_animation.h"
#include "core/sh/sh_window.h"
#include "core/sun/sun_light.h"
#include "core/pipeline/stage.h"

namespace arpipe {

// What turns light.panorama.lights_file's photometric lights into the render's direct lights
// (its lights_scale, the penumbra's source size) and names the file in messages.
struct SceneLightUnits {
  double lights_scale = 1;
  double angular_diameter_rad = 0;
  std::filesystem::path file;
};

class LightStage final : public Stage {
 public:
  std::string_view name() const override { return "light"; }
  // Throws ConfigError naming the key on a probe or sun setting that cannot work; the old setup
  // then stays.
  void configure(const Config& config) override;
  // light.source = "environment": the HDR file is read and projected by the loader, off the
  // processing thread on a reload; configure_loaded() only takes the result.
  StageAssetLoader asset_loader() const override;
  void configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) override;
  // Fixed: records the skip and leaves ctx.light for the renderer's fixed light. Probe and sun:
  // the estimate, Held or None with a note when this frame could not be measured.
  void process(FrameContext& ctx) noexcept override;

 private:
  LightSource source_ = LightSource::Fixed;
  std::unique_ptr<ProbeLightEstimator> probe_;
  std::unique_ptr<SunLight> sun_;
  LightEstimate environment_;  // Environment: the same every frame
  struct PanoramaLighting {
    std::vector<DirectionalLight> direct;  // lights_file's, else render.light_* unless direct_light_from_render is off
    ShWindow window = ShWindow::None;
    // lights_file's animation, when it moves a light: the lights posed at each frame's time.
    std::shared_ptr<const GltfAnimation> animation;
    SceneLightUnits units;
    std::optional<int64_t> posed_at_ns = int64_t{0};
  } panorama_;                   // Panorama: with the SH each frame brings
  void pose_scene_lights(FrameContext& ctx) noexcept;
  Vec3 probe_centre_{0, 0, 0};
  LightHold hold_;  // the probe's measurements within their noise of the last light keep it
  Vec3 ground_albedo_{0.3, 0.3, 0.3};
  CameraResponse response_;
  GroundRadiance ground_;
  double probe_light_distance_m_ = 0;
  std::string last_note_;  // logged once per distinct note
};

}  // namespace arpipe
