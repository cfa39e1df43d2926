// Draws one frame's visible virtual objects into a premultiplied texture on the draw canvas: sharp
// (at mid-exposure of each row), or smeared over the exposure by one of the render.blur methods.
// Every method works only inside the footprint rectangle; a frame whose image motion is below
// render.blur.min_motion_px takes the sharp path and costs what it would without blur.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/config.h"
#include "core/geometry/camera_model.h"
#include "core/motion/shutter_motion.h"
#include "render/blur/accumulation_pass.h"
#include "render/object_renderer.h"
#include "render/blur/intraframe_warp_blur_pass.h"
#include "render/gl/texture_target.h"
#include "render/blur/velocity_blur_pass.h"
#include "render/virtual_layer.h"
#include "render/work_area.h"

namespace arpipe {


// What one frame's draw needs, in the coordinates of the canvas drawn on (the lens image, or the
// pinhole canvas with render.lens = "map").
struct LayerDrawRequest {
  const ShutterMotion* motion = nullptr;   // nullptr or None: no motion known
  SE3 T_cam_world;                         // the frame's pose (mid-exposure)
  std::vector<const UploadedObject*> objects;
  LensUniforms lens;                       // the projection the shaders draw with
  const CameraModel* canvas_camera = nullptr;  // the same projection on the CPU (seed's box corners)
  RowProjection rows;                      // which row of the real image a camera point lies on
  Lighting lighting;
  PixelRect rect;                          // canvas pixels that the objects can reach over the exposure
  // With catcher_under: the ground catcher (objects.back(), no proxy among objects) is drawn after
  // the multisampled objects, under them, at one sample per pixel (ObjectRenderer::
  // draw_ground_catcher_under); objects_rect (within rect) is what the others can reach.
  bool catcher_under = false;
  PixelRect objects_rect;
  // With catcher_under: no object reaches below the ground and no camera centre lies below it, so
  // the ground hides nothing and its depth (which hides what of an object is below it) is not drawn.
  bool ground_hides_nothing = false;
  double image_motion_px = 0;              // ShutterMotion::max_image_motion_px
  int msaa_samples = 4;
  bool rolling_shutter = true;
  double occluder_lod_px = 0;              // render.occluder_lod_px
};

struct LayerDrawResult {
  GLuint texture = 0;                 // premultiplied, canvas-sized, valid inside the request's rect
  BlurMethod method = BlurMethod::Off;  // what was done: Off when drawn sharp
  int samples = 0;                    // blur samples (renders, warps or gather taps); 0 when sharp
  std::string_view sharp_because;     // when drawn sharp with a blur method configured: why
};

class MotionBlurDrawer {
 public:
  // Compiles the sharp path; needs a current context. Throws RenderError.
  MotionBlurDrawer(const EglContext& context, GLenum layer_format);
  // Compiles what a method needs now rather than on its first blurred frame.
  void prepare(BlurMethod method);
  void prepare_shadows(ShadowMethod method) { objects_.prepare(method); }
  ObjectRenderer& objects() { return objects_; }  // for the ground catcher's bake

  LayerDrawResult draw(VirtualLayer& layer, const LayerDrawRequest& request, const BlurConfig& config);

 private:
  void draw_at(VirtualLayer& layer, const LayerDrawRequest& request, double exposure_fraction);
  LayerDrawResult draw_accumulated(VirtualLayer& layer, const LayerDrawRequest& request, int samples);
  LayerDrawResult draw_intraframe_warp(VirtualLayer& layer, const LayerDrawRequest& request, int fixed_samples);
  LayerDrawResult draw_velocity(VirtualLayer& layer, const LayerDrawRequest& request, int samples);

  const EglContext& context_;
  GLenum layer_format_;
  ObjectRenderer objects_;
  std::unique_ptr<AccumulationPass> accumulation_;  // each made on first use
  std::unique_ptr<IntraframeWarpBlurPass> seed_;
  std::unique_ptr<VelocityBlurPass> velocity_;
  TextureTarget first_intraframe_;
  TextureTarget velocity_image_;
  WorkAreaChooser objects_area_chooser_;  // the objects' multisampled image with catcher_under
  WorkArea objects_area_;                 // this frame's
};

}  // namespace arpipe
