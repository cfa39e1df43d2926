// The render stage: draws the scene's virtual objects, seen from the tracked pose through the
// calibrated lens (render.lens: warped canvas, per-vertex distortion, or the undistorted pinhole
// core), into the shared virtual layer (linear, premultiplied alpha, depth-tested).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/pipeline/stage.h"
#include "render/layer_reuse.h"
#include "render/lens/lens_mode.h"
#include "render/lens/lens_warp_map.h"
#include "render/lens/lens_warp_pass.h"
#include "render/blur/motion_blur.h"
#include "render/lens/per_model_cache.h"
#include "render/proxy_animator.h"
#include "render/uploaded_objects.h"
#include "render/render_session.h"
#include "render/scene_physics.h"
#include "render/occlusion_meter.h"
#include "render/shadow/shadow_map.h"
#include "render/shadow/catcher_bake.h"
#include "render/shadow/shadow_receiver.h"
#include "render/shadow/unshadowed_objects.h"

namespace arpipe {

class RenderStage final : public Stage {
 public:
  explicit RenderStage(std::shared_ptr<RenderSession> session);
  ~RenderStage() override;

  std::string_view name() const override { return "render"; }
  // Creates the GL context on the first call (on this thread), compiles the shaders once, and
  // loads the meshes; throws RenderError, ConfigError or AssetError and then keeps the old setup.
  // configure_loaded() does the same with meshes already loaded by asset_loader() (reading the
  // meshes and baking their PRT transfers happen there, off the processing thread); only the GPU
  // upload is left for the processing thread.
  void configure(const Config& config) override;
  StageAssetLoader asset_loader() const override;
  void configure_loaded(const Config& config, const std::shared_ptr<const StageAssets>& assets) override;
  // With render.lens = "map", builds the camera model's warp map (mrcal, a few hundred ms at
  // 640x480) before streaming starts; "undistort": its pinhole core. A frame with another model
  // builds its own on its first drawn frame.
  void prepare(const std::shared_ptr<const CameraModel>& camera_model) noexcept override;
  // Drawn: ctx.virtual_layer_drawn, and ctx.virtual_layer names the texture for the composite stage.
  // Skips (ctx.virtual_layer_drawn = false, reason recorded) when rendering is off, there are no
  // objects, there is no pose (neither Tracking nor Predicted within
  // render.max_predicted_uncertainty_deg), or no object's box reaches into the
  // image; such frames do no GL work. Blurs by render.blur when the frame's motion asks for it.
  // Hands the last layer on again (drawn, with the skip reason "reused: ...") when the objects, the
  // pose over the exposure and the light are unchanged within LayerReuse's tolerances.
  void process(FrameContext& ctx) noexcept override;

 private:
  struct Settings {
    bool enabled = true;
    int msaa_samples = 4;
    Vec3 light_direction{0, 0, 1};
    double light_distance_m = 0;
    Vec3 light_color{1, 1, 1};
    Vec3 ambient{0, 0, 0};
    LensMode lens = LensMode::Map;
    double lens_canvas_scale = 1.5;
    bool rolling_shutter = true;
    double max_predicted_uncertainty_deg = 5.0;
    bool reuse_layer = true;
    bool full_canvas = false;
    OdsRig ods;  // a stereo panorama source's (source.panorama), for its eyes' frames
    double occluder_lod_px = 0.1;
    int64_t default_exposure_ns = 0;  // motion.default_exposure_ms: for objects that move themselves
    BlurConfig blur;
    ShadowConfig shadows;
    ShadowMethod shadow_method = ShadowMethod::Off;
  };
  enum class Drawn { Yes, Reused, OutOfView };
  Drawn draw(FrameContext& ctx);
  // Cuts the objects and proxies and splits the catcher for a stereo panorama's eyes, once.
  void prepare_for_stereo();
  Lighting frame_lighting(const FrameContext& ctx, double& angular_diameter_rad) const;
  // The shadow map for this frame's light, or nullptr (ctx gets a "shadow" timing saying why).
  // redrawn: whether the map changed (a layer drawn with the old one cannot be reused).
  const ShadowLookup* shadow_for(FrameContext& ctx, Lighting& lighting, double angular_diameter_rad,
                                 std::vector<const UploadedObject*>& drawn, bool& redrawn);
  // Steps the physics to the frame's exposure end and places the moving objects at its middle;
  // whether any of them moved since the last frame.
  bool move_objects(const ShutterMotion& motion);
  // Where each present object's shadow can fall in the image (its box's shadow volume down to the
  // ground), in objects_'s order less the absent ones; an empty rectangle when out of view;
  // nullopt when one cannot be bounded (a grazing light).
  std::optional<std::vector<PixelRect>> shadow_volume_rects(const CameraModel& camera, const SE3& T_cam_world,
                                                            const Lighting& lighting) const;
  // The largest image motion of a moving object's box corners over the exposure (its own blur).
  double moving_objects_motion_px(const ShutterMotion& motion, const CameraModel& camera) const;
  std::shared_ptr<const LensWarpMap> warp_map(const std::shared_ptr<const CameraModel>& camera_model);
  std::shared_ptr<const CameraModel> pinhole_core(const std::shared_ptr<const CameraModel>& camera_model);

  std::shared_ptr<RenderSession> session_;  // first member: outlives the GL objects below
  std::unique_ptr<MotionBlurDrawer> drawer_;  // the objects' programs and the blur passes
  std::unique_ptr<LensWarpPass> warp_pass_;  // made by configure with render.lens = "map"
  std::unique_ptr<ShadowMapPass> shadow_pass_;  // made by configure unless render.shadows.method = "off"
  std::unique_ptr<ShadowReceiver> receiver_;
  std::unique_ptr<CatcherBake> catcher_bake_;  // made on the first frame with a shadow
  std::unique_ptr<ShadowMapPass> real_shadow_pass_;  // the casting proxies alone (made when there are any)
  Vec3 shadow_light_direction_{0, 0, 0};  // what the shadow map was made for (moves in steps)
  double shadow_filter_reach_m_ = 0;        // how far from a point this frame's shadow lookups read
  PerModelCache<LensWarpMap> warp_maps_;
  PerModelCache<CameraModel> pinhole_cores_;  // render.lens = "undistort": what the output sees
  std::vector<UploadedObject> objects_;
  std::vector<UploadedObject> proxies_;  // [[render.proxies]], in config order
  std::unique_ptr<ProxyAnimator> animator_;  // places the animated ones among proxies_ per frame
  // Whether objects_ and proxies_ are cut for a stereo panorama's eyes (uploaded_objects.h); the meshes and the
  // config they came from, to cut them when an "auto" layout's first eye's frame comes.
  bool cut_for_stereo_ = false;
  std::shared_ptr<const StageAssets> assets_;
  Config proxy_config_;
  std::unique_ptr<ScenePhysics> physics_;  // nullptr when no object has a physics kind
  std::unique_ptr<OcclusionMeter> occlusion_meter_;  // with proxies or physics: ctx.objects
  LayerReuse reuse_;
  Settings settings_;
  std::string last_error_;  // logged once per distinct message, not once per frame
};

}  // namespace arpipe
