// How much of each virtual object the phantom proxies hide in a frame, for results.jsonl and
// /state: rays through a grid over the object's box in the image (the lens's pinhole core, a
// 24 x 24 grid: each ray is 1/576 of the box, far finer than the share is read at) meet the
// object's mesh and the occluding proxies' meshes (Embree, on the CPU); the share of the rays that
// meet the object with a proxy nearer, and which proxy.
#pragma once

#include <memory>
#include <vector>

#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/pipeline/object_report.h"
#include "render/prt/prt_ray_scene.h"
#include "render/uploaded_objects.h"

namespace arpipe {

class OcclusionMeter {
 public:
  static constexpr int kGrid = 24;

  // Builds the ray scenes of the config's object and proxy meshes (as loaded for the render stage).
  OcclusionMeter(const Config& config, const LoadedMeshes& meshes);
  ~OcclusionMeter();

  // One report per object of `objects` (as placed for this frame), seen from T_cam_world, hidden
  // by the proxies at the frame's viewpoint (proxy_at_viewpoint). A stereo panorama's eye: each
  // ray leaves that eye's place on the circle about world z (core/geometry/ods_projection.h).
  std::vector<ObjectReport> measure(const CameraModel& camera, const SE3& T_cam_world,
                                    const std::vector<UploadedObject>& objects,
                                    const std::vector<UploadedObject>& proxies, const std::optional<int>& viewpoint = {},
                                    Eye eye = Eye::Mono, const OdsRig& rig = {}) const;

 private:
  std::vector<std::shared_ptr<const PrtRayScene>> object_scenes_;  // per render.objects entry
  std::vector<std::shared_ptr<const PrtRayScene>> proxy_scenes_;   // per render.proxies entry
};

}  // namespace arpipe
