// "Pose unchanged: reuse the virtual layer" (docs/DESIGN.md's skips): decides whether this frame's
// virtual layer would be the one drawn last, within tolerances well under what the picture can
// show, so the render stage can hand the last layer on instead of drawing it again.
//
// The same picture needs the same objects seen from the same place through the same lens with the
// same light:
// - every corner of every drawn object's box, at every instant of the exposure that bounds the
//   blur path, moves by at most kMaxMotionPx pixels (bounded on the CPU without the lens: a point
//   at depth z displaced by d in the camera frame moves at most about f * d / z pixels);
// - the light's direction turns by at most kMaxLightTurnRad, and every light value (direct and
//   ambient colour, each SH coefficient, the exposure scale) changes by at most kMaxLightChange
//   of the largest, so no pixel's shade moves by a 1/255 step;
// - the same camera model, draw settings and object set (configure() forgets the last layer).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/pipeline/frame_context.h"
#include "render/object_renderer.h"
#include "core/image/pixel_rect.h"

namespace arpipe {

// Whether two frames' lights draw the same picture, exposure aside: the same kind and shadow map,
// turned less than LayerReuse::kMaxLightTurnRad (a lamp moved less than that many metres), and
// no value (direct, ambient, the ground's, SH) apart by more than kMaxLightChange of the largest.
bool same_light(const Lighting& a, const Lighting& b);

class LayerReuse {
 public:
  // Well under a pixel, and above the tracker's own frame-to-frame noise on a still camera (0.09 to
  // 0.15 px at the default cube's corners on the tag-static capture), so that a still camera
  // reuses its layer, and the object then stands still instead of jittering with that noise.
  static constexpr double kMaxMotionPx = 0.25;
  static constexpr double kMaxLightTurnRad = 1e-4;  // a shadow 10 cm long moves 0.01 mm
  static constexpr double kMaxLightChange = 1e-3;   // 0.1 % of the brightest value, a quarter of 1/255

  // What one frame's layer depends on.
  struct Inputs {
    std::shared_ptr<const CameraModel> camera_model;
    std::vector<SE3> exposure_poses;  // T_cam_world at the instants that bound the exposure
    std::vector<const UploadedObject*> objects;  // what is drawn, the shadow catcher included
    Lighting lighting;
    bool shadow_map_redrawn = false;  // the shadow map changed since the last layer
    PixelRect rect;
    Eye eye = Eye::Mono;  // a stereo panorama's eyes see from different places
  };

  // Whether the last layer can be shown again for these inputs. The first frame after forget()
  // always draws.
  bool can_reuse(const Inputs& inputs) const;
  // The layer just drawn for these inputs, and what the stage reported with it.
  void remember(Inputs inputs, const VirtualLayerTexture& layer, std::string blur_method, int blur_samples);
  void forget() { have_last_ = false; }

  const VirtualLayerTexture& layer() const { return layer_; }
  const std::string& blur_method() const { return blur_method_; }
  int blur_samples() const { return blur_samples_; }

 private:
  bool have_last_ = false;
  Inputs last_;
  VirtualLayerTexture layer_;
  std::string blur_method_;
  int blur_samples_ = 0;
};

// The most any corner of the objects' boxes moves on the image between two camera poses, bounded as
// above; infinity when a corner is (nearly) behind the camera in either.
double max_corner_motion_px(const CameraModel& camera, const std::vector<const UploadedObject*>& objects,
                            const SE3& T_cam_world_a, const SE3& T_cam_world_b);

}  // namespace arpipe
