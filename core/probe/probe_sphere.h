// A light-probe sphere at a known place in the world and where it lies in a camera image: the
// silhouette through the lens model, and each pixel's true view ray hitting the sphere analytically.
#pragma once

#include <cstdint>
#include <vector>

#include "core/config/probe_kind.h"
#include "core/geometry/camera_model.h"
#include "core/geometry/se3.h"
#include "core/geometry/vec.h"
#include "core/light/linear_patch.h"

namespace arpipe {

struct ProbeSphere {
  using Kind = ProbeKind;  // core/config/probe_kind.h: the config key light.probe.kind
  Kind kind = Kind::Mirror;
  Vec3 center_world{0, 0, 0};
  double radius_m = 0.04;
  double reflectance = 0.9;  // mirror: specular reflectance (scalar); diffuse: albedo
};

// Unit view rays of a camera's pixels (camera frame), unprojected through mrcal on first use and
// kept: mrcal's unproject of a distorted model is an iterative solve per pixel (measured in
// bench/probe_analysis), and the probe covers mostly the same pixels frame after frame.
class PixelRayCache {
 public:
  // Makes sure the rays of `rect` are known for this model (resets when the model changes).
  void prepare(const CameraModel& model, const ImageRect& rect);
  // The ray of pixel (x, y) after prepare() covered it; z = 0 when mrcal could not unproject it.
  const float* ray(int x, int y) const { return &rays_[(size_t(y) * size_t(width_) + size_t(x)) * 3]; }

 private:
  std::vector<double> key_;  // intrinsics + size of the model the table belongs to
  int width_ = 0, height_ = 0;
  std::vector<float> rays_;  // NaN: not computed yet
};

// One pixel whose view ray hits the sphere, away from the silhouette.
struct ProbeHit {
  int x = 0, y = 0;
  Vec3 normal_world;        // outward unit normal at the hit point
  Vec3 view_world;          // unit ray from the camera centre to the hit point
  double distance_m = 0;    // camera centre to hit point
  double pixel_solid_angle = 0;  // of the pixel seen from the camera (sr)
};

struct ProbeRegion {
  bool in_front = false;        // the whole sphere lies in front of the camera
  ImageRect rect;               // bounding rect of the silhouette, clipped to the image
  double rim_in_image = 0;      // fraction of the silhouette's rim samples inside the image
  double radius_px = 0;         // apparent radius (mean rim distance from the centre's image)
  Vec2 center_px{0, 0};
  Vec3 camera_world{0, 0, 0};   // camera centre in the world frame
  std::vector<ProbeHit> hits;   // sphere pixels, rim pixels excluded
  std::vector<int32_t> index;   // rect-sized: index into hits, -1 off the sphere or on its rim
  int rim_pixels = 0;           // pixels on the sphere that were excluded as mixed
  int hit_at(int x, int y) const {
    return rect.contains(x, y) ? index[size_t(y - rect.y0) * size_t(rect.width) + size_t(x - rect.x0)] : -1;
  }
};

inline constexpr int kProbeRimSamples = 64;
// Pixels whose centre ray passes within this many pixels of the silhouette are mixed (sphere and
// background) and left out.
inline constexpr double kProbeRimMarginPx = 1.0;

// Fills `out` for this pose; false when the sphere is not wholly in front of the camera or its
// rect misses the image (out.in_front / rim_in_image then say why). Never throws.
bool compute_probe_region(const ProbeSphere& sphere, const CameraModel& model, const SE3& T_cam_world,
                          PixelRayCache& rays, ProbeRegion& out);

// Where the ray from the camera centre along unit `view_world` first meets the sphere; false when
// it misses (then `normal` is the closest point's normal, on the silhouette).
bool intersect_probe(const ProbeSphere& sphere, const Vec3& camera_world, const Vec3& view_world, Vec3& point,
                     Vec3& normal);

// GLSL reflect(): the incident direction i mirrored about the unit normal n, i - 2 (i.n) n.
inline Vec3 reflect(const Vec3& i, const Vec3& n) { return i - (2 * dot(i, n)) * n; }

}  // namespace arpipe
