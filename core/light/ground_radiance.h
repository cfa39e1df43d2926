// The real ground's brightness around the anchor: the median scene-linear radiance on a ring of
// the plane z = 0, which with the ground's albedo gives the light falling on it.
#pragma once

#include <optional>
#include <vector>

#include "core/frame.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/image/camera_response.h"
#include "core/light/light_estimate.h"
#include "core/light/linear_patch.h"

namespace arpipe {

class GroundRadiance {
 public:
  // nullopt when too little of the ring is in view or unclipped.
  std::optional<Vec3> measure(const Frame& frame, const CameraModel& camera, const SE3& T_cam_world,
                              const CameraResponse& response);

 private:
  std::vector<LinearPixel> pixels_;  // the ring's, kept for its buffer
};

// A light whose probe pixels were clipped is only known as a lower bound. The ground it falls on
// says how strong it is: radiance = albedo / pi * (E cos + ambient irradiance), solved for E per
// channel. Leaves the light alone when that gives less than the bound or the light grazes the
// ground; true when it changed it.
bool light_from_ground(DirectionalLight& light, const ShRgb9& ambient_sh, const Vec3& ground_radiance,
                       const Vec3& ground_albedo);

}  // namespace arpipe
